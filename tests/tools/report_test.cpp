// Tests of `parrender report` (tools/cmd_report.cpp, tools/report/): every registered method
// and schedule has its class, the Amdahl and Karp-Flatt fit recovers a known serial fraction,
// and a small report made as a user would make it opens in headless Chromium with no script
// error, every chart drawn and every image loaded (the screenshot is kept under
// <build>/test-artifacts), and replaces an earlier report only once it is whole.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "common/image/image_io.h"
#include "common/parallel/schedulers/scheduler.h"
#include "common/util/error.h"
#include "raster/sort/sort_point.h"
#include "raytrace/partition/partition.h"
#include "test_support.h"
#include "tools/report/classification.h"
#include "tools/report/scaling_model.h"

using pr::test::join;
using pr::test::quoted;
using pr::test::runCommand;
using pr::test::runParrender;

namespace {

std::string readText(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The value of attribute `name` of the page's <body> after its scripts ran, or "".
std::string bodyAttribute(const std::string& dom, const std::string& name) {
  std::smatch m;
  const std::regex body("<body[^>]*\\s" + name + "=\"([^\"]*)\"");
  return std::regex_search(dom, m, body) ? m[1].str() : std::string();
}

bool haveChromium() {
  if (runCommand("command -v chromium").exitStatus == 0) return true;
  std::printf("SKIPPED: chromium not found (tools/setup.sh installs it)\n");
  return false;
}

}  // namespace

TEST_CASE("Report: every registered method and schedule has its place in the seed's classification") {
  std::set<std::string> names;
  for (const pr::rt::PartitionInfo& p : pr::rt::partitions()) names.insert(p.name);
  for (const pr::raster::SortPointInfo& s : pr::raster::sortPoints()) names.insert(s.name);
  CHECK(names.size() >= 8);
  for (const std::string& n : names) {
    CAPTURE(n);
    const pr::cli::report::MethodClass k = pr::cli::report::classifyMethod(n);
    CHECK_FALSE(k.subdivision.empty());
    CHECK_FALSE(k.dataManagement.empty());
    CHECK(k.seedSection.rfind("§", 0) == 0);
  }
  CHECK(pr::cli::report::classifyMethod("sort-middle").sortPoint.rfind("sort-middle", 0) == 0);
  for (const pr::par::ScheduleInfo& s : pr::par::schedules()) {
    CAPTURE(s.name);
    CHECK_FALSE(pr::cli::report::classifySchedule(s.name).model.empty());
  }
  CHECK_THROWS_AS(pr::cli::report::classifyMethod("warp-drive"), pr::InputError);
}

TEST_CASE("Report: the Karp-Flatt fit recovers the serial fraction of speed-ups that follow Amdahl's law") {
  using namespace pr::cli::report;
  const double f = 0.15;
  std::vector<std::pair<int, double>> points = {{1, 1.0}};
  for (int p : {2, 4, 8}) points.emplace_back(p, amdahlSpeedup(f, p));
  CHECK(fittedSerialFraction(points) == doctest::Approx(f));
  CHECK(amdahlSpeedup(0.0, 16) == doctest::Approx(16.0));
  CHECK(amdahlSpeedup(1.0, 16) == doctest::Approx(1.0));
  CHECK(std::isnan(fittedSerialFraction({{1, 1.0}})));
  CHECK(powersOfTwo(1024).size() == 11);
}

TEST_CASE("Report: a small report opens offline in headless Chromium with every chart and image drawn") {
  const std::filesystem::path dir = pr::test::scratchDir("report");
  const std::filesystem::path out = dir / "report";
  const std::string args =
      join({"report ", quoted(pr::test::sourceDir() / "scenes" / "cornell.gltf"), " -o ", quoted(out),
            " --width 32 --height 24 --threads 1,2 --schedules demand --repeat 1 --spp 1 --max-depth 3",
            " --reference-spp 8 --photons 1000 --caustic-photons 200 --photon-spp 1,2 --gather 8 --path-spp 1,2 --max-pes 64",
            " --reference-dir ", quoted(dir / "refs")});
  const auto r = runParrender(args);
  INFO(r.output);
  REQUIRE(r.exitStatus == 0);
  for (const char* file : {"index.html", "page.js", "lib/vega.min.js", "lib/vega-lite.min.js", "lib/vega-embed.min.js",
                           "cornell/comparison.csv", "cornell/comparison.json", "cornell/timeline.trace.json",
                           "cornell/img/reference.png", "cornell/img/sort-last_diff8.png"}) {
    CAPTURE(file);
    CHECK(std::filesystem::exists(out / file));
  }
  const std::string html = readText(out / "index.html");
  CHECK(html.find("src=\"http") == std::string::npos);  // nothing fetched from the network
  CHECK(html.find("Classification") != std::string::npos);
  CHECK(html.find("Verdict") != std::string::npos);
  // No class's claim about traffic is contradicted by the measured runs at P = 2.
  CHECK(html.find("CONTRADICTED") == std::string::npos);
  CHECK(html.find("holds: 0 ray messages") != std::string::npos);  // image-space
  CHECK(html.find(" bytes composited</td>") != std::string::npos);  // sort-last
  // The data beside every chart.
  int charts = 0;
  for (const char* name : {"speedup", "efficiency", "per_pe", "gantt", "communication", "composite_analytic", "cache", "accuracy"}) {
    CAPTURE(name);
    std::ifstream in(out / "cornell" / (std::string(name) + ".json"));
    const nlohmann::json data = nlohmann::json::parse(in);
    CHECK(data.is_array());
    CHECK(data.size() > 0);
    ++charts;
  }
  // The data manager's hit ratio: one point per cache size, none at 0 MiB, most at the largest,
  // and every cache size gave the same image.
  {
    std::ifstream in(out / "cornell" / "cache.json");
    const nlohmann::json data = nlohmann::json::parse(in);
    REQUIRE(data.size() == 6);
    CHECK(data.front()["cacheMiB"].get<double>() == 0.0);
    CHECK(data.front()["hitRatio"].get<double>() == 0.0);
    CHECK(data.back()["hitRatio"].get<double>() > 0.5);
    for (std::size_t i = 1; i < data.size(); ++i) CHECK(data[i]["hitRatio"].get<double>() >= data[0]["hitRatio"].get<double>());
    CHECK(html.find("Every cache size gave the comparison's image bit for bit") != std::string::npos);
  }
  // The sort-last compositing bytes equal the analytic volume (full frame).
  {
    std::ifstream in(out / "cornell" / "composite_analytic.json");
    const nlohmann::json data = nlohmann::json::parse(in);
    REQUIRE(data.size() == 2);
    CHECK(data[0]["bytes"].get<double>() == doctest::Approx(data[1]["bytes"].get<double>()));
  }

  if (!haveChromium()) return;
  const std::string url = pr::test::quoted("file://" + std::filesystem::absolute(out / "index.html").string());
  const std::string chromium = "chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --virtual-time-budget=20000 ";
  const auto dom = runCommand(join({chromium, "--dump-dom ", url, " 2>/dev/null"}));
  REQUIRE(dom.exitStatus == 0);
  INFO(dom.output.substr(0, 2000));
  CHECK(bodyAttribute(dom.output, "data-errors") == "0");
  CHECK(bodyAttribute(dom.output, "data-chart-total") == std::to_string(charts));
  CHECK(bodyAttribute(dom.output, "data-charts") == std::to_string(charts));
  const std::string images = bodyAttribute(dom.output, "data-image-total");
  CHECK(std::stoi(images.empty() ? "0" : images) >= 10);
  CHECK(bodyAttribute(dom.output, "data-images") == images);
  std::size_t svgs = 0;
  for (std::size_t at = dom.output.find("<svg"); at != std::string::npos; at = dom.output.find("<svg", at + 1)) ++svgs;
  CHECK(svgs >= std::size_t(charts));

  // The page's own check can fail: with one chart's spec broken it counts the error and that
  // chart is not drawn.
  {
    const std::filesystem::path broken = dir / "broken";
    std::filesystem::copy(out, broken, std::filesystem::copy_options::recursive);
    std::string page = readText(broken / "index.html");
    const std::size_t at = page.find("\"mark\":\"bar\"");
    REQUIRE(at != std::string::npos);
    page.replace(at, 12, "\"mark\":\"no such mark\"");
    std::ofstream(broken / "index.html") << page;
    const auto bad = runCommand(join({chromium, "--dump-dom ",
                                      pr::test::quoted("file://" + std::filesystem::absolute(broken / "index.html").string()),
                                      " 2>/dev/null"}));
    CHECK(bodyAttribute(bad.output, "data-errors") != "0");
    CHECK(bodyAttribute(bad.output, "data-charts") == std::to_string(charts - 1));
  }

  // The screenshot, kept as the test's artefact, is not blank.
  const std::filesystem::path artefacts = pr::test::binaryDir() / "test-artifacts";
  std::filesystem::create_directories(artefacts);
  const std::filesystem::path shot = artefacts / "report.png";
  std::filesystem::remove(shot);
  runCommand(join({chromium, "--window-size=1400,3000 --screenshot=", quoted(shot), " ", url}));
  REQUIRE(std::filesystem::exists(shot));
  const pr::image::Image picture = pr::image::readImage(shot);
  std::set<std::tuple<int, int, int>> colours;
  for (const glm::vec3& p : picture.pixels) colours.insert({int(p.x * 255.0f), int(p.y * 255.0f), int(p.z * 255.0f)});
  CHECK(colours.size() > 50);
}

namespace {

// An earlier report in dir/report (its page and marker), which a new one is to replace.
std::filesystem::path earlierReport(const std::filesystem::path& dir) {
  const std::filesystem::path out = dir / "report";
  std::filesystem::create_directories(out);
  { std::ofstream(out / "index.html") << "the earlier report"; }
  { std::ofstream(out / ".parrender-report") << "a report"; }
  return out;
}

}  // namespace

// Interrupted while it renders, the report leaves the earlier one in place and nothing of the
// new one: its folder, filling beside the earlier one, goes with the interrupt.
TEST_CASE("Report: an interrupted report leaves the earlier one in place and no half-written folder") {
  const std::filesystem::path dir = pr::test::scratchDir("report_interrupt");
  const std::filesystem::path out = earlierReport(dir);
  const std::string report = join({quoted(PARRENDER_EXE), " report ", quoted(pr::test::sourceDir() / "scenes" / "cornell.gltf"),
                                   " -o ", quoted(out), " --width 64 --height 64 --threads 1 --repeat 1 --spp 4096 --reference-dir ",
                                   quoted(dir / "refs")});
  // Waits (up to 30 s) until the new report's folder has something in it, then interrupts.
  const std::string script = "timeout 120 " + report + " & p=$!; for i in $(seq 300); do [ -n \"$(ls -A " +
                             quoted(dir) + "/.report.new-* 2>/dev/null)\" ] && break; sleep 0.1; done; sleep 0.5; "
                             "kill -INT $p; wait $p; echo status=$?";
  const std::filesystem::path scriptFile = dir / "interrupt.sh";
  std::ofstream(scriptFile) << script << "\n";
  const auto r = runCommand("bash " + quoted(scriptFile));
  INFO(r.output);
  CHECK(r.output.find("status=130") != std::string::npos);
  CHECK(readText(out / "index.html") == "the earlier report");
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    CAPTURE(name);
    CHECK(name.find(".report.") == std::string::npos);  // no new or old folder left beside it
  }
}

TEST_CASE("Report: a report that fails leaves the earlier one in place and no half-written folder") {
  const std::filesystem::path dir = pr::test::scratchDir("report_atomic");
  const std::filesystem::path out = earlierReport(dir);
  const std::string args = join({"report ", quoted(pr::test::sourceDir() / "scenes" / "cornell.gltf"), " -o ", quoted(out),
                                 " --width 8 --height 8 --threads 1 --repeat 1"});
  const auto failed = runCommand(join({"PARRENDER_REPORT_SCRIPTS=", quoted(dir / "nowhere"), " \"", PARRENDER_EXE, "\" ", args}));
  INFO(failed.output);
  CHECK(failed.exitStatus == 2);
  CHECK(failed.output.find("tools/setup.sh") != std::string::npos);
  CHECK(readText(out / "index.html") == "the earlier report");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++entries;
  CHECK(entries == 1);  // only the earlier report: no new or old folder left beside it

  // A report made whole takes the earlier one's place.
  const auto made = runParrender(join({args, " --spp 1 --reference-spp 2 --photon-spp 1 --path-spp 1 --max-pes 4 --reference-dir ",
                                       quoted(dir / "refs")}));
  INFO(made.output);
  CHECK(made.exitStatus == 0);
  CHECK(readText(out / "index.html").find("<!DOCTYPE html>") == 0);
  CHECK(std::filesystem::exists(out / ".parrender-report"));
  entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++entries;
  CHECK(entries == 2);  // the report and the reference cache

  // A folder that is not a report is never replaced.
  const std::filesystem::path mine = dir / "mine";
  std::filesystem::create_directories(mine);
  { std::ofstream(mine / "notes.txt") << "someone's file"; }
  const auto refused = runParrender(join({"report ", quoted(pr::test::sourceDir() / "scenes" / "cornell.gltf"), " -o ",
                                          quoted(mine), "/ --width 8 --height 8 --threads 1 --repeat 1"}));
  CHECK(refused.exitStatus == 2);
  CHECK(refused.output.find("not a parrender report") != std::string::npos);
  CHECK(readText(mine / "notes.txt") == "someone's file");
  std::filesystem::remove_all(mine);

  const auto bad = runParrender(join({"report ", quoted(pr::test::sourceDir() / "scenes" / "cornell.gltf"), " -o ", quoted(out),
                                      " --threads 2"}));
  CHECK(bad.exitStatus == 2);
  CHECK(bad.output.find("--threads must include 1") != std::string::npos);
  const auto help = runParrender("report --help");
  CHECK(help.exitStatus == 0);
  CHECK(help.output.find("--network") != std::string::npos);
}

TEST_CASE("Report: an image that differs from its family's fails the report and stays out of its verdict") {
  const std::filesystem::path dir = pr::test::scratchDir("report_mismatch");
  const std::filesystem::path out = dir / "report";
  // image-space, the faster of the two here, has one pixel of its every image changed (a test
  // fault; object-space's P = 1 image, the first of the family, is the one the others must
  // equal): it is the fastest of nothing, and the command fails once the report is written.
  const std::string args = join({"report ", quoted(pr::test::sourceDir() / "scenes" / "cornell.gltf"), " -o ", quoted(out),
                                 " --methods object-space,image-space --schedules demand --width 16 --height 12 --threads 1,2",
                                 " --repeat 1 --spp 1 --reference-spp 2 --photon-spp 1 --path-spp 1 --max-pes 4 --reference-dir ",
                                 quoted(dir / "refs")});
  const auto r = runCommand(join({"PARRENDER_IMAGE_FAULT=image-space \"", PARRENDER_EXE, "\" ", args}));
  INFO(r.output);
  CHECK(r.exitStatus == 1);
  CHECK(r.output.find("IMAGE MISMATCH: image-space") != std::string::npos);
  CHECK(r.output.find("2 render(s) differ from their family's image") != std::string::npos);
  const std::string html = readText(out / "index.html");
  CHECK(html.find("2 renders differ from their family's image: none of them is chosen as the fastest") != std::string::npos);
  const std::size_t verdict = html.find("<h3>Verdict</h3>");
  REQUIRE(verdict != std::string::npos);
  const std::string text = html.substr(verdict);
  CHECK(text.find("the fastest is <b>image-space") == std::string::npos);
  CHECK(text.find("the fastest is <b>object-space") != std::string::npos);
  CHECK(text.find("the simulator predicts <b>image-space") == std::string::npos);
  // Without the fault the same report passes, and shows its reasoning: each prediction beside
  // the measurement at the same P, and how each stage was replayed at the largest P.
  const auto good = runParrender(args);
  INFO(good.output);
  CHECK(good.exitStatus == 0);
  const std::string page = readText(out / "index.html");
  CHECK(page.find("s measured (") != std::string::npos);
  CHECK(page.find("how each stage was replayed at P = 4") != std::string::npos);
  CHECK(page.find("build: single owner") != std::string::npos);  // image-space's BVH, serial at any P
}

TEST_CASE("Report: a class's claim about traffic is checked against the measured run, and a contradiction is flagged") {
  using pr::cli::report::checkClaim;
  using pr::cli::report::MeasuredTraffic;
  CHECK(checkClaim("image-space", MeasuredTraffic{2, 0, 0, 0.0}) == "holds: 0 ray messages");
  CHECK(checkClaim("image-space", MeasuredTraffic{2, 3, 0, 0.0}) == "CONTRADICTED: 3 ray messages");
  CHECK(checkClaim("object-space", MeasuredTraffic{2, 3, 0, 0.0}) == "holds: 3 ray messages");
  CHECK(checkClaim("object", MeasuredTraffic{2, 0, 0, 0.0}) == "not shown here: 0 ray messages");
  CHECK(checkClaim("sort-middle", MeasuredTraffic{4, 0, 7, 0.0}) == "holds: 7 primitive messages");
  CHECK(checkClaim("sort-first", MeasuredTraffic{4, 0, 0, 0.0}) == "not shown here: 0 primitive messages");
  CHECK(checkClaim("sort-last", MeasuredTraffic{2, 0, 0, 4096.0}) == "holds: 4096 bytes composited");
  CHECK(checkClaim("sort-last", MeasuredTraffic{2, 0, 0, 0.0}) == "not shown here: 0 bytes composited");
  CHECK(checkClaim("object-space", MeasuredTraffic{1, 0, 0, 0.0}) == "-");  // one PE cannot say
  CHECK(checkClaim("image-space-cached", MeasuredTraffic{2, 0, 0, 0.0}) == "-");
}
