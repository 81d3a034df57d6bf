// `parrender render` across processes: mpirun on loopback (--oversubscribe, root allowed as in
// CI), each command under `timeout` so a failure can never hang the suite. The image of every
// R x T equals the single-process image bit for bit; the run record of R = 2 ranks of one PE
// counts the same messages and bytes per kind as the thread runtime at P = 2; methods that do
// not run across ranks yet, and the other commands, refuse with one message.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <map>
#include <utility>
#include <string>

#include "common/image/image_io.h"
#include "common/parallel/metrics.h"
#include "common/parallel/run_record.h"
#include "mpirun_support.h"

using pr::test::cornell;
using pr::test::CommandResult;
using pr::test::join;
using pr::test::occurrences;
using pr::test::quoted;

namespace {

CommandResult mpiParrender(int ranks, const std::string& args) { return pr::test::mpirun(ranks, quoted(PARRENDER_EXE), args, 120); }

std::string cornellGlass() { return quoted(pr::test::sourceDir() / "scenes" / "cornell-glass.gltf"); }

// Renders `args` in one process of one PE, then under mpirun at each R x T: the same image bit
// for bit, rank 0 alone printing, P = R x T.
void checkEqualsOneProcess(const std::string& name, const std::string& method, const std::string& args,
                           std::initializer_list<std::array<int, 2>> shapes, const std::string& scene = cornell()) {
  const std::filesystem::path dir = pr::test::scratchDir("render_ranks_" + name);
  const std::string common = join({"render ", scene, " -m ", method, " ", args, " --quiet"});
  const std::filesystem::path reference = dir / "reference.exr";
  const CommandResult one = pr::test::runParrender(join({common, " --threads 1 -o ", quoted(reference)}));
  INFO(one.output);
  REQUIRE(one.exitStatus == 0);
  const pr::image::Image expected = pr::image::readImage(reference);
  for (const std::array<int, 2>& shape : shapes) {
    const int ranks = shape[0], threads = shape[1];  // CAPTURE cannot take a structured binding
    CAPTURE(ranks);
    CAPTURE(threads);
    const std::filesystem::path out = dir / (std::to_string(ranks) + "x" + std::to_string(threads) + ".exr");
    const CommandResult r = mpiParrender(ranks, join({common, " --threads ", std::to_string(threads), " -o ", quoted(out)}));
    INFO(r.output);
    REQUIRE(r.exitStatus == 0);
    CHECK(occurrences(r.output, "method " + method) == 1);  // rank 0 alone prints
    CHECK(r.output.find("P " + std::to_string(ranks * threads) + " (" + std::to_string(ranks) + " ranks x " +
                        std::to_string(threads) + " PEs)") != std::string::npos);
    CHECK(pr::image::readImage(out).pixels == expected.pixels);
  }
}

// The ray tracers' options of the record comparisons: 48x48, 1 spp, tiles of 8, a static schedule.
const std::string kRayRecordArgs = "--integrator path --width 48 --height 48 --spp 1 --tile-size 8 --schedule balanced";

// `command` (a render) with --threads T, in one process (R = 1) or under mpirun on R ranks,
// its image and run record written into dir as NAME.png and NAME.json: what it printed and
// the record.
std::pair<std::string, pr::par::RunRecord> renderRecord(const std::string& command, int ranks, int threads,
                                                        const std::filesystem::path& dir, const std::string& name) {
  const std::string args = join({command, " --threads ", std::to_string(threads), " -o ", quoted(dir / (name + ".png")),
                                 " --metrics ", quoted(dir / (name + ".json"))});
  const CommandResult r = ranks == 1 ? pr::test::runParrender(args) : mpiParrender(ranks, args);
  INFO(r.output);
  REQUIRE(r.exitStatus == 0);
  return {r.output, pr::par::readRunRecord(dir / (name + ".json"))};
}

// The run records of `method` on the Cornell box with `args` at P = 2: two PE threads in one
// process, and two ranks of one PE under mpirun.
std::pair<pr::par::RunRecord, pr::par::RunRecord> threadsAndRanksRecords(const std::filesystem::path& dir,
                                                                       const std::string& method,
                                                                       const std::string& args = kRayRecordArgs) {
  const std::string common = join({"render ", cornell(), " -m ", method, " ", args, " --quiet"});
  return {renderRecord(common, 1, 2, dir, "threads").second, renderRecord(common, 2, 1, dir, "ranks").second};
}

// The messages, and their bytes, of each channel in each stage of two records.
void checkSameTraffic(const pr::par::RunRecord& t, const pr::par::RunRecord& r) {
  REQUIRE(r.stages.size() == t.stages.size());
  for (std::size_t s = 0; s < t.stages.size(); ++s) {
    CAPTURE(t.stages[s].name);
    CHECK(r.stages[s].name == t.stages[s].name);
    REQUIRE(r.stages[s].channels.size() == t.stages[s].channels.size());
    for (std::size_t c = 0; c < t.stages[s].channels.size(); ++c) {
      CHECK(r.stages[s].channels[c].kind == t.stages[s].channels[c].kind);
      CHECK(r.stages[s].channels[c].messages == t.stages[s].channels[c].messages);
      CHECK(r.stages[s].channels[c].bytes == t.stages[s].channels[c].bytes);
    }
  }
}

}  // namespace

TEST_CASE("RenderRanks: image-space across R = 2, 3, 4 ranks of 1 and 2 PEs equals the single-process image") {
  for (const char* integrator : {"whitted", "path"}) {
    CAPTURE(integrator);
    checkEqualsOneProcess(std::string("image_space_") + integrator, "image-space",
                          join({"--integrator ", integrator, " --width 40 --height 32 --spp 2 --tile-size 8"}),
                          {{2, 1}, {2, 2}, {3, 1}, {3, 2}, {4, 1}, {4, 2}});
  }
}

// Object-space: rays cross ranks as messages between the owners of the voxels along them, the
// split made on rank 0 and sent; path tracing sends continuation and shadow rays too.
TEST_CASE("RenderRanks: object-space across R = 2, 3 ranks of 1 and 2 PEs equals the single-process image") {
  checkEqualsOneProcess("object_space", "object-space", "--integrator path --width 40 --height 32 --spp 2 --tile-size 8",
                        {{2, 1}, {2, 2}, {3, 1}, {3, 2}});
}

// Object partitioning: queries go to the owners of the pieces a ray can reach and hit replies
// come back across ranks; rank 0 makes the assignment and sends it, and chooses the tiles'
// preferred PEs from the probe hits gathered from every rank (preferred-bias uses them).
TEST_CASE("RenderRanks: object partitioning across R = 2, 3 ranks of 1 and 2 PEs equals the single-process image") {
  for (const char* schedule : {"demand", "preferred-bias"}) {
    CAPTURE(schedule);
    checkEqualsOneProcess(std::string("object_") + schedule, "object",
                          join({"--integrator path --width 40 --height 32 --spp 2 --tile-size 8 --schedule ", schedule}),
                          {{2, 1}, {2, 2}, {3, 1}});
  }
}

// Image-space with a data manager: a PE fetches the geometry items (a piece's BVH and vertex
// data) it does not own from their owners, across ranks as the items' encoding, decoded
// against the receiver's own scene; with a cache too small for every item, with and without
// latency hiding, under a schedule with a cost pre-pass.
TEST_CASE("RenderRanks: image-space-cached across R = 2, 3 ranks of 1 and 2 PEs equals the single-process image") {
  checkEqualsOneProcess("cached", "image-space-cached", "--integrator path --width 40 --height 32 --spp 2 --tile-size 8 --cache-mb 0.05",
                        {{2, 1}, {2, 2}, {3, 1}});
  // A static schedule from the cost pre-pass's estimates: every rank must deal the same tiles
  // (each tile traced once), so the estimates are summed across ranks.
  checkEqualsOneProcess("cached_blocking", "image-space-cached",
                        "--integrator whitted --width 40 --height 32 --spp 1 --tile-size 8 --no-latency-hiding --schedule unbalanced",
                        {{2, 1}, {3, 1}});
}

// The photon map: photons are traced where the tracer traces rays, gathered to rank 0 and sent
// on to every rank, which builds the same maps (a replicated build, one task per rank); the
// precomputed irradiance and each level of the irradiance cache are computed in parallel and
// every rank receives every point, coverage flag, gather sample and record, so every rank
// renders with the same cache. The glass box has caustics as well as indirect light.
TEST_CASE("RenderRanks: the photon map across R = 2, 3 ranks of 1 and 2 PEs equals the single-process image") {
  const std::string args = "--integrator photonmap --width 48 --height 40 --spp 4 --photons 20000 --caustic-photons 20000 --gather 16";
  checkEqualsOneProcess("photonmap_image_space", "image-space", args, {{2, 1}, {2, 2}, {3, 1}}, cornellGlass());
  checkEqualsOneProcess("photonmap_object_space", "object-space", args, {{2, 1}, {3, 1}}, cornellGlass());
  checkEqualsOneProcess("photonmap_object", "object", args, {{2, 1}, {2, 2}}, cornellGlass());
}

// Sort-first: primitives cross ranks as their data, installed into the receiving PE's own copy
// of the scene, in which every vertex it was not given is NaN (its share came from PE 0 the
// same way); dynamic regions pull a tile's primitives from every rank. Two orbit frames, so the
// second sends only the primitives that changed owner.
TEST_CASE("RenderRanks: sort-first across R = 2, 3, 4 ranks of 1 and 2 PEs equals the single-process image") {
  const std::string args = "--width 64 --height 48 --tile 16 --frames 2 --orbit --regions ";
  checkEqualsOneProcess("sort_first_static", "sort-first", args + "static-tiles", {{2, 1}, {2, 2}, {3, 1}, {4, 1}});
  checkEqualsOneProcess("sort_first_dynamic", "sort-first", args + "dynamic", {{2, 1}, {3, 1}});
}

// Sort-middle: screen triangles cross ranks to the regions' owners (static tiles and strips), or
// a tile's bins are pulled from every rank by the PE the demand-driven pool gave it (dynamic);
// the finished regions go to the assembler on rank 0.
TEST_CASE("RenderRanks: sort-middle across R = 2, 3, 4 ranks of 1 and 2 PEs equals the single-process image") {
  const std::string args = "--width 64 --height 48 --tile 16 --frames 2 --orbit --regions ";
  checkEqualsOneProcess("sort_middle_tiles", "sort-middle", args + "static-tiles", {{2, 1}, {2, 2}, {3, 1}, {4, 1}});
  checkEqualsOneProcess("sort_middle_strips", "sort-middle", args + "static-strips", {{2, 1}, {3, 1}});
  checkEqualsOneProcess("sort_middle_dynamic", "sort-middle", args + "dynamic", {{2, 1}, {2, 2}, {3, 1}});
}

// Sort-last: every PE's fragments are depth-composited across ranks (direct-send, binary-swap;
// full frame and sparse), each region shaded by its owner and sent to rank 0. Two frames, so
// the second frame's strips are cut by the row costs summed across ranks.
TEST_CASE("RenderRanks: sort-last across R = 2, 3, 4 ranks of 1 and 2 PEs equals the single-process image") {
  checkEqualsOneProcess("sort_last_direct", "sort-last", "--width 64 --height 48 --frames 2 --orbit --compositor direct-send",
                        {{2, 1}, {2, 2}, {3, 1}, {3, 2}});
  checkEqualsOneProcess("sort_last_swap_sparse", "sort-last",
                        "--width 64 --height 48 --frames 2 --orbit --compositor binary-swap --sparse",
                        {{2, 1}, {2, 2}, {4, 1}});
}

// Static regions and compositing strips are decided alike on every rank, and under a static
// schedule the geometry batches fall on the same PEs, so the sort points send the same
// messages, of the same encoded sizes, whether the two PEs are threads or ranks; the Sort/
// counters agree PE by PE.
TEST_CASE("RenderRanks: the sort points on 2 ranks of one PE send what the thread runtime at P = 2 sends") {
  for (const std::string method : {"sort-first", "sort-middle", "sort-last"}) {
    CAPTURE(method);
    // A static schedule: the geometry batches fall on the same PEs whatever the timing.
    const auto records = threadsAndRanksRecords(pr::test::scratchDir("render_ranks_record_" + method), method,
                                                "--width 64 --height 48 --tile 16 --regions static-tiles --schedule balanced");
    const pr::par::RunRecord& t = records.first;
    const pr::par::RunRecord& r = records.second;
    CHECK(r.pes == 2);
    checkSameTraffic(t, r);
    for (const pr::par::CounterRecord& c : t.counters) {
      if (c.name.rfind("Sort/", 0) != 0) continue;
      CAPTURE(c.name);
      const auto it = std::find_if(r.counters.begin(), r.counters.end(), [&](const pr::par::CounterRecord& x) { return x.name == c.name; });
      REQUIRE(it != r.counters.end());
      CHECK(it->perPe == c.perPe);
    }
  }
}

TEST_CASE("RenderRanks: the record of 2 ranks of one PE counts what the thread runtime at P = 2 counts, and P = R x T") {
  const std::filesystem::path dir = pr::test::scratchDir("render_ranks_record");
  const std::string common = join({"render ", cornell(), " -m image-space --integrator path --width 48 --height 48 --spp 1 "
                                   "--tile-size 8 --schedule balanced --quiet"});
  const auto records = threadsAndRanksRecords(dir, "image-space");  // CAPTURE cannot take a structured binding
  const pr::par::RunRecord& t = records.first;
  const pr::par::RunRecord& r = records.second;
  CHECK(r.pes == 2);
  checkSameTraffic(t, r);
  for (std::size_t s = 0; s < t.stages.size(); ++s) {
    CAPTURE(t.stages[s].name);
    // The world BVH is built on each rank (a replicated computation, on its first PE), once
    // on one rank; every other stage's tasks fall on the same PEs.
    const bool build = t.stages[s].name == "build";
    for (int p = 0; p < 2; ++p) {
      CHECK(r.stages[s].pes[std::size_t(p)].tasks == (build ? 1u : t.stages[s].pes[std::size_t(p)].tasks));
      CHECK(r.stages[s].pes[std::size_t(p)].messagesReceived == t.stages[s].pes[std::size_t(p)].messagesReceived);
    }
  }
  // Four PEs on two ranks: the record has them all, each with its tasks.
  const pr::par::RunRecord f = renderRecord(common, 2, 2, dir, "four").second;
  CHECK(f.pes == 4);
  const pr::par::StageRecord& trace = f.stages.back();
  for (int p = 0; p < 4; ++p) CHECK(trace.pes[std::size_t(p)].tasks > 0);
}

// With a static schedule every ray takes the same way from owner to owner whatever the
// timing, so the rays crossing between the two PEs are the same ones, encoded in the same
// bytes, whether the PEs are threads or ranks (the number of batches is not: a batch leaves
// when its PE runs dry).
TEST_CASE("RenderRanks: object-space on 2 ranks of one PE sends the rays, and their bytes, of the thread runtime at P = 2") {
  const auto records = threadsAndRanksRecords(pr::test::scratchDir("render_ranks_object_record"), "object-space");
  const pr::par::RunRecord& t = records.first;
  const pr::par::RunRecord& r = records.second;
  const auto raysChannel = [](const pr::par::RunRecord& record) {
    for (const pr::par::StageRecord& stage : record.stages)
      for (const pr::par::ChannelTraffic& c : stage.channels)
        if (c.name == "rays") return c;
    FAIL("no rays channel in the record");
    return pr::par::ChannelTraffic{};
  };
  const pr::par::ChannelTraffic tr = raysChannel(t), rr = raysChannel(r);
  CHECK(tr.bytes > 0);
  CHECK(rr.bytes == tr.bytes);
  const auto raysSent = [](const pr::par::RunRecord& record) {
    const auto it = std::find_if(record.counters.begin(), record.counters.end(),
                                 [](const pr::par::CounterRecord& c) { return c.name == "Partition/rays_sent"; });
    REQUIRE(it != record.counters.end());
    return it->perPe;
  };
  CHECK(raysSent(r) == raysSent(t));
  // The split is made once on rank 0's PE and decoded on rank 1's: one task on each.
  const auto split = std::find_if(r.stages.begin(), r.stages.end(), [](const pr::par::StageRecord& s) { return s.name == "split"; });
  REQUIRE(split != r.stages.end());
  CHECK(split->pes[0].tasks == 1);
  CHECK(split->pes[1].tasks == 1);
}

// Messages and bytes per kind of a run, with the replicated copies a rank made itself (loaded
// the scene, built the BVH) counted as the broadcasts one process books for them.
std::map<std::string, std::array<std::uint64_t, 2>> trafficWithReplicas(const pr::par::RunRecord& record) {
  std::map<std::string, std::array<std::uint64_t, 2>> kinds;
  for (const pr::par::KindTraffic& k : pr::par::summarize(record).total.byKind) kinds[k.kind] = {k.messages, k.bytes};
  for (const pr::par::StageRecord& s : record.stages)
    for (const pr::par::PeStageRecord& pe : s.pes)
      if (pe.replicatedCopies > 0) {
        kinds["broadcasts"][0] += pe.replicatedCopies;
        kinds["broadcasts"][1] += pe.replicatedBytes;
      }
  return kinds;
}

// Every method and integrator, on the glass Cornell box (area light, glass, caustics), under a
// static schedule: R = 2 ranks of T PEs count, kind by kind, the messages and bytes that the
// thread runtime at P = 2T counts - a figure does not change with the transport. What one
// process broadcasts and the ranks make for themselves (the scene each loaded, the BVH each
// built) is named as replicated in the ranks' record and counted once per copy like a
// broadcast. Ray batches leave when a PE runs dry, so only their bytes must agree.
TEST_CASE("RenderRanks: every method's record on 2 ranks counts, kind by kind, what the thread runtime counts at the same P") {
  const std::filesystem::path dir = pr::test::scratchDir("render_ranks_kinds");
  struct Case {
    std::string method, integrator;
    int threads;  // per rank
  };
  std::vector<Case> cases;
  for (const char* method : {"image-space", "image-space-cached", "object-space", "object"})
    for (const char* integrator : {"whitted", "path", "photonmap"}) cases.push_back({method, integrator, 1});
  for (const char* method : {"sort-first", "sort-middle", "sort-last"}) cases.push_back({method, "", 1});
  cases.push_back({"image-space", "photonmap", 2});
  cases.push_back({"object", "photonmap", 2});
  cases.push_back({"sort-middle", "", 2});
  for (const Case& c : cases) {
    CAPTURE(c.method);
    CAPTURE(c.integrator);
    CAPTURE(c.threads);
    std::string command = join({"render ", cornellGlass(), " -m ", c.method, " --width 32 --height 24 --schedule balanced --quiet"});
    if (!c.integrator.empty()) command += join({" --integrator ", c.integrator, " --spp 1 --tile-size 8"});
    if (c.integrator == "photonmap") command += " --photons 3000 --caustic-photons 3000 --gather 8";
    const pr::par::RunRecord t = renderRecord(command, 1, 2 * c.threads, dir, "threads").second;
    const pr::par::RunRecord r = renderRecord(command, 2, c.threads, dir, "ranks").second;
    CHECK(r.pes == t.pes);
    const auto tk = trafficWithReplicas(t), rk = trafficWithReplicas(r);
    CHECK(tk.count("broadcasts") == 1);
    for (const auto& [kind, figures] : tk) {
      CAPTURE(kind);
      REQUIRE(rk.count(kind) == 1);
      CHECK(rk.at(kind)[1] == figures[1]);
      if (kind != "rays") CHECK(rk.at(kind)[0] == figures[0]);
    }
    CHECK(rk.size() == tk.size());
  }
}

// The record says which traffic crossed between the ranks: every channel message between two
// PEs on different ranks (the per-pair figures say which pairs those are), the task traffic of
// PEs that asked rank 0's controller, and each broadcast's copy to every other rank's first
// PE; in one process nothing crosses.
TEST_CASE("RenderRanks: the record splits every kind of traffic into what crossed between ranks and what stayed within one") {
  const std::filesystem::path dir = pr::test::scratchDir("render_ranks_split");
  const std::string common = join({"render ", cornell(), " -m object-space --integrator path --width 48 --height 48 --spp 1 "
                                   "--tile-size 8 --quiet"});
  const auto [printed, r] = renderRecord(common, 2, 2, dir, "ranks");
  CHECK(printed.find("between ranks: ") != std::string::npos);
  CHECK(printed.find("replicated on the other ranks (loaded or built there, not sent): 1 copies") != std::string::npos);
  REQUIRE(r.ranks == 2);
  REQUIRE(r.pes == 4);
  const auto rankOf = [](int pe) { return pe / 2; };
  std::uint64_t crossingPairs = 0, crossingChannels = 0, channels = 0, crossingBroadcasts = 0, taskCrossings = 0;
  std::uint64_t askedTasks = 0;  // tasks rank 1's PEs got from rank 0's controller (demand)
  for (const pr::par::StageRecord& s : r.stages) {
    for (const pr::par::Traffic& t : s.traffic)
      if (rankOf(t.from) != rankOf(t.to)) crossingPairs += t.messages;
    for (const pr::par::ChannelTraffic& c : s.channels) {
      CHECK(c.betweenRankMessages <= c.messages);
      crossingChannels += c.betweenRankMessages;
      channels += c.messages;
    }
    for (int p = 0; p < 4; ++p) {
      const pr::par::PeStageRecord& pe = s.pes[std::size_t(p)];
      if (p == 2) crossingBroadcasts += pe.broadcastsReceived;
      if (p < 2) CHECK(pe.schedulingMessagesBetweenRanks == 0);  // rank 0 asks its own controller
      taskCrossings += pe.schedulingMessagesBetweenRanks;
      if (p >= 2 && s.schedule == "demand") askedTasks += pe.tasks;
    }
  }
  CHECK(crossingChannels > 0);
  CHECK(crossingChannels < channels);
  CHECK(crossingChannels == crossingPairs);
  // Whether rank 1's PEs got any task depends on timing (rank 0's may take them all under
  // load); each one it got crossed as a request and an answer.
  if (askedTasks > 0) CHECK(taskCrossings > 0);
  CHECK(crossingBroadcasts > 0);
  const pr::par::RunSummary summary = pr::par::summarize(r);
  for (const pr::par::KindTraffic& k : summary.total.byKind) {
    CAPTURE(k.kind);
    if (k.kind == "broadcasts") CHECK(k.betweenRankMessages == crossingBroadcasts);
    if (k.kind == "tasks") CHECK(k.betweenRankMessages == taskCrossings);
  }
  // One process: ranks 1, nothing between ranks.
  const pr::par::RunRecord t = renderRecord(common, 1, 4, dir, "threads").second;
  CHECK(t.ranks == 1);
  for (const pr::par::KindTraffic& k : pr::par::summarize(t).total.byKind) {
    CAPTURE(k.kind);
    CHECK(k.messages > 0);
    CHECK(k.betweenRankMessages == 0);
  }
}

// The photons gathered to rank 0 reach every other rank as a broadcast of their bytes, booked
// in the share stage on each other rank's first PE (the PEs that read their rank's copy are
// booked after it); in one process the controlling thread already holds them: no share stage,
// nothing moves, and the same broadcast is booked for every PE but PE 0.
TEST_CASE("RenderRanks: the photon map's share of the gathered photons between ranks is a booked broadcast") {
  const std::filesystem::path dir = pr::test::scratchDir("render_ranks_photon_share");
  const std::string common = join({"render ", cornellGlass(), " -m image-space --integrator photonmap --width 24 --height 20 "
                                   "--spp 1 --photons 4000 --caustic-photons 4000 --gather 8 --quiet"});
  const pr::par::RunRecord r = renderRecord(common, 2, 2, dir, "ranks").second;
  const auto share = std::find_if(r.stages.begin(), r.stages.end(),
                                  [](const pr::par::StageRecord& s) { return s.name.find("photon merge share") != std::string::npos; });
  REQUIRE(share != r.stages.end());
  CHECK(share->broadcasts == 1);
  CHECK(share->broadcastBytes > 4000u * 16u);  // the photons stored (each more than 16 bytes)
  CHECK(share->pes[2].broadcastsReceived == 1);
  CHECK(share->pes[2].broadcastBytesReceived == share->broadcastBytes);
  for (int p : {0, 1, 3}) CHECK(share->pes[std::size_t(p)].broadcastsReceived == 0);
  const pr::par::RunRecord t = renderRecord(common, 1, 4, dir, "threads").second;
  CHECK(std::none_of(t.stages.begin(), t.stages.end(),
                     [](const pr::par::StageRecord& s) { return s.name.find("share") != std::string::npos; }));
  const auto merge = std::find_if(t.stages.begin(), t.stages.end(),
                                  [](const pr::par::StageRecord& s) { return s.name == "photon merge"; });
  REQUIRE(merge != t.stages.end());
  REQUIRE(merge + 1 != t.stages.end());
  for (int p = 0; p < 4; ++p) CHECK((merge + 1)->pes[std::size_t(p)].broadcastBytesReceived == (p == 0 ? 0u : share->broadcastBytes));
}

TEST_CASE("RenderRanks: what does not run across ranks exits 2 with one message from rank 0, and so do --help and bad options") {
  // The sequential tracer is the one-PE reference: it has no ranks to run on.
  const CommandResult sequential = mpiParrender(2, join({"render ", cornell(), " -m sequential --width 8 --height 8 -o /tmp/never.png"}));
  CHECK(sequential.exitStatus == 2);
  CHECK(occurrences(sequential.output, "method sequential does not run across processes") == 1);
  CHECK(sequential.output.find("image-space, image-space-cached, object-space, object, sort-first, sort-middle, sort-last") !=
        std::string::npos);
  // So is the raster family's.
  const CommandResult sequentialRaster =
      mpiParrender(2, join({"render ", cornell(), " -m sequential-raster --width 8 --height 8 -o /tmp/never.png"}));
  CHECK(sequentialRaster.exitStatus == 2);
  CHECK(occurrences(sequentialRaster.output, "method sequential-raster does not run across processes") == 1);
  // CLI11's output is rank 0's alone, and every rank ends through the group.
  const CommandResult help = mpiParrender(2, "--help");
  CHECK(help.exitStatus == 0);
  CHECK(occurrences(help.output, "render a glTF scene") == 1);
  const CommandResult badOption = mpiParrender(2, join({"render ", cornell(), " --width 0"}));
  CHECK(badOption.exitStatus == 2);
  CHECK(occurrences(badOption.output, "Run with --help for more information") == 1);
  const CommandResult info = mpiParrender(2, join({"info ", cornell()}));
  CHECK(info.exitStatus == 2);
  CHECK(occurrences(info.output, "'info' does not run across processes") == 1);
}

// An interrupt on one rank ends every rank: the interrupted rank removes what it was writing
// and exits 128 + signal, mpirun ends the others, and no image is left behind; nothing hangs
// (the render would run for minutes; the command is bounded by timeout). SIGTERM, since a
// background job of a non-interactive shell ignores SIGINT.
TEST_CASE("RenderRanks: a rank interrupted during a render ends every rank, with no output left") {
  const std::filesystem::path dir = pr::test::scratchDir("render_ranks_interrupt");
  const std::filesystem::path out = dir / "interrupted.png";
  const std::string render = join({quoted(PARRENDER_EXE), " render ", cornell(), " -m image-space --integrator path --spp 4096 "
                                   "--width 256 --height 256 --threads 1 --quiet -o ", quoted(out)});
  // Waits (up to 30 s) until both ranks run, then interrupts the second one found.
  const std::string ranks = "pgrep -f -- '^" + std::string(PARRENDER_EXE) + " render .*interrupted.png'";
  const std::string script = pr::test::kMpiEnv + " timeout 90 mpirun --oversubscribe -np 2 " + render +
                             " & m=$!; for i in $(seq 300); do [ $(" + ranks + " | wc -l) -ge 2 ] && break; sleep 0.1; done; "
                             "sleep 1; kill -TERM $(" + ranks + " | tail -1); wait $m; echo status=$?";
  const std::filesystem::path scriptFile = dir / "interrupt.sh";
  std::ofstream(scriptFile) << script << "\n";
  const CommandResult r = pr::test::runCommand("bash " + quoted(scriptFile));
  INFO(r.output);
  CHECK(r.output.find("status=124") == std::string::npos);  // ended by the interrupt, not the timeout
  CHECK(r.output.find("status=0") == std::string::npos);
  CHECK(r.output.find("parrender: interrupted; outputs in progress removed") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(out));
}

// --max-memory is each rank's: a rank's estimate is for its own T PEs, and a render that would
// exceed it is refused before it starts, with one message from rank 0 and exit 2 everywhere.
TEST_CASE("RenderRanks: --max-memory applies to each rank, and a refusal is one message from rank 0") {
  const CommandResult r = mpiParrender(2, join({"render ", cornell(), " --max-memory 200K --threads 2 -o /tmp/never.png"}));
  CHECK(r.exitStatus == 2);
  CHECK(occurrences(r.output, "exceeds the memory limit of 200.0 KiB") == 1);
  CHECK(r.output.find("(rank 0 of 2)") != std::string::npos);
  CHECK(r.output.find("at P = 2,") != std::string::npos);  // the rank's two PEs, not the run's four
  CHECK_FALSE(std::filesystem::exists("/tmp/never.png"));
}
