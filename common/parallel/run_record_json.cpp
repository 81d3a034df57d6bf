// RunRecord as JSON (--metrics FILE) and as a Chrome trace (--trace FILE), and back from JSON
// for `parrender simulate`. Keys are the C++ field names (shared/STYLE.md §2). The derived
// "summary" block is written from metrics.cpp for readers; it is ignored when reading.
// Timeline spans are compact arrays [pe, stage, task, start, end, messagesSent, bytesSent].
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "common/parallel/cell_split.h"
#include "common/parallel/farm/farm_record_json.h"
#include "common/parallel/metrics.h"
#include "common/parallel/run_record.h"
#include "common/util/atomic_file.h"
#include "common/util/error.h"

namespace pr::par {

using nlohmann::json;

std::vector<double> taskCostProfile(const RunRecord& record, int stage) {
  PR_CHECK(stage >= 0 && stage < static_cast<int>(record.stages.size()), "taskCostProfile: no such stage");
  std::vector<double> costs(record.stages[stage].tasks.size(), 0.0);
  for (const TaskSpan& span : record.timeline)
    if (span.stage == stage && span.task >= 0 && span.task < static_cast<TaskId>(costs.size()))
      costs[span.task] += std::max(0.0, span.end - span.start - span.waitSeconds);  // what it computed
  return costs;
}

namespace {

json spreadJson(const Spread& s) { return {{"min", s.min}, {"mean", s.mean}, {"max", s.max}}; }

json summaryJson(const StageSummary& s) {
  json j = {{"wallSeconds", s.wallSeconds},     {"imbalance", s.imbalance},
            {"utilisation", s.utilisation},     {"syncWaitSeconds", s.syncWaitSeconds},
            {"tasks", s.tasks},                 {"messages", s.messages},
            {"bytes", s.bytes},                 {"schedulingMessages", s.schedulingMessages},
            {"schedulingBytes", s.schedulingBytes}};
  j["computeToComm"] = s.computeToComm >= 0.0 ? json(s.computeToComm) : json(nullptr);
  json kinds = json::object();
  for (const KindTraffic& k : s.byKind)
    kinds[k.kind] = {{"messages", k.messages}, {"bytes", k.bytes}, {"betweenRankMessages", k.betweenRankMessages},
                     {"betweenRankBytes", k.betweenRankBytes}};
  j["trafficByKind"] = kinds;
  json perPe = json::object();
  const auto& figures = peFigures();
  for (std::size_t i = 0; i < figures.size(); ++i) perPe[figures[i].name] = spreadJson(s.figures[i]);
  j["perPe"] = perPe;
  return j;
}

json peJson(const PeStageRecord& r) {
  return {{"busySeconds", r.busySeconds},
          {"idleSeconds", r.idleSeconds},
          {"syncWaitSeconds", r.syncWaitSeconds},
          {"sendReceiveSeconds", r.sendReceiveSeconds},
          {"messageWaitSeconds", r.messageWaitSeconds},
          {"commSeconds", r.commSeconds()},
          {"tasks", r.tasks},
          {"messagesHandled", r.messagesHandled},
          {"messagesSent", r.messagesSent},
          {"bytesSent", r.bytesSent},
          {"messagesReceived", r.messagesReceived},
          {"bytesReceived", r.bytesReceived},
          {"schedulingMessages", r.schedulingMessages},
          {"schedulingBytes", r.schedulingBytes},
          {"schedulingMessagesBetweenRanks", r.schedulingMessagesBetweenRanks},
          {"schedulingBytesBetweenRanks", r.schedulingBytesBetweenRanks},
          {"broadcastsReceived", r.broadcastsReceived},
          {"broadcastBytesReceived", r.broadcastBytesReceived},
          {"replicatedCopies", r.replicatedCopies},
          {"replicatedBytes", r.replicatedBytes},
          {"cacheHits", r.cacheHits},
          {"cacheMisses", r.cacheMisses},
          {"prefetches", r.prefetches}};
}


json toJson(const RunRecord& record) {
  json j;
  j["pes"] = record.pes;
  j["ranks"] = record.ranks;
  j["schedule"] = record.schedule;
  j["grain"] = record.grain;
  j["wallSeconds"] = record.wallSeconds;
  j["error"] = record.error;
  const RunSummary summary = summarize(record);
  j["summary"] = summaryJson(summary.total);
  j["summary"]["serialFraction"] = summary.total.serialFraction;
  json provenance = json::object();
  for (const PeFigure& f : peFigures()) provenance[f.name] = f.provenance;
  j["figureProvenance"] = provenance;  // per figure: "measured" or "modelled: how"

  json stages = json::array();
  for (std::size_t i = 0; i < record.stages.size(); ++i) {
    const StageRecord& s = record.stages[i];
    json js = {{"name", s.name},
               {"schedule", s.schedule},
               {"grain", s.grain},
               {"startSeconds", s.startSeconds},
               {"wallSeconds", s.wallSeconds},
               {"broadcasts", s.broadcasts},
               {"broadcastBytes", s.broadcastBytes},
               {"summary", summaryJson(summary.stages[i])}};
    if (summary.stages[i].serial) js["summary"]["serial"] = true;
    json pes = json::array();
    for (const PeStageRecord& r : s.pes) pes.push_back(peJson(r));
    js["pes"] = pes;
    json traffic = json::array();
    for (const Traffic& t : s.traffic)
      traffic.push_back({{"from", t.from}, {"to", t.to}, {"messages", t.messages}, {"bytes", t.bytes}});
    js["traffic"] = traffic;
    json channels = json::array();
    for (const ChannelTraffic& c : s.channels)
      channels.push_back({{"name", c.name}, {"kind", c.kind}, {"messages", c.messages}, {"bytes", c.bytes},
                          {"betweenRankMessages", c.betweenRankMessages}, {"betweenRankBytes", c.betweenRankBytes}});
    js["channels"] = channels;
    json tasks = json::array();
    for (const TaskInfo& t : s.tasks) tasks.push_back({t.costEstimate, t.x, t.y});
    js["tasks"] = tasks;  // [costEstimate, x, y]
    // The PE holding each task's data, where a renderer named one (preferred-bias regions).
    if (std::any_of(s.tasks.begin(), s.tasks.end(), [](const TaskInfo& t) { return t.preferredPe >= 0; })) {
      json preferred = json::array();
      for (const TaskInfo& t : s.tasks) preferred.push_back(t.preferredPe);
      js["preferred"] = preferred;
    }
    if (!s.owners.empty()) js["owners"] = s.owners;  // owner-pinned stages: the PE of each task
    if (!s.kind.empty()) js["kind"] = s.kind;
    if (!s.cellSplit.empty()) {
      js["cellSplit"] = s.cellSplit;
      js["cellCount"] = s.cellCount;
      js["cellCollector"] = s.cellCollector;
    }
    stages.push_back(js);
  }
  j["stages"] = stages;
  json timeline = json::array();
  for (const TaskSpan& t : record.timeline)
    timeline.push_back({t.pe, t.stage, t.task, t.start, t.end, t.messagesSent, t.bytesSent, t.waitSeconds});
  j["timeline"] = timeline;
  if (!record.cells.empty()) {
    json cells = json::array();
    for (const CellSpan& c : record.cells) cells.push_back({c.pe, c.stage, c.cell, c.seconds, c.resultBytes});
    j["cells"] = cells;  // [pe, stage, cell, seconds, resultBytes]
  }
  json counters = json::array();
  for (const CounterRecord& c : record.counters) counters.push_back({{"name", c.name}, {"perPe", c.perPe}});
  j["counters"] = counters;
  if (record.farm) j["farm"] = farmJson(*record.farm);
  return j;
}

void writeText(const std::string& text, const std::filesystem::path& file, const char* what) {
  writeFileAtomically(file, text, std::string(what) + " file");
}

// A JSON number as T, or InputError naming what: a value T cannot hold (a negative count, 1e300
// as a PE, 2.5 as a task index) is malformed input, not a silent wrap or an undefined
// conversion.
template <class T>
T numberAs(const json& v, const std::string& what) {
  if (!v.is_number()) throw InputError(what + " must be a number");
  if constexpr (std::is_floating_point_v<T>) {
    const double d = v.get<double>();
    if (std::isfinite(d) && std::abs(d) > static_cast<double>(std::numeric_limits<T>::max()))
      throw InputError(what + " is out of range");
    return static_cast<T>(d);
  } else {
    using Limits = std::numeric_limits<T>;
    if (v.is_number_unsigned()) {
      const auto u = v.get<std::uint64_t>();
      if (u > static_cast<std::uint64_t>(Limits::max())) throw InputError(what + " is out of range");
      return static_cast<T>(u);
    }
    if (v.is_number_integer()) {
      const auto i = v.get<std::int64_t>();
      if (i < 0 ? i < static_cast<std::int64_t>(Limits::min())
                : static_cast<std::uint64_t>(i) > static_cast<std::uint64_t>(Limits::max()))
        throw InputError(what + " is out of range");
      return static_cast<T>(i);
    }
    // A float that is a whole number within T's range (2^digits is exact as a double).
    const double d = v.get<double>();
    const double bound = std::ldexp(1.0, Limits::digits);
    if (!(d == std::trunc(d) && d < bound && d >= (Limits::is_signed ? -bound : 0.0)))
      throw InputError(what + " must be a whole number in range");
    return static_cast<T>(d);
  }
}

// Reads key from object j, or throws InputError naming origin, where and key.
template <class T>
T field(const json& j, const char* key, const std::string& origin, const std::string& where) {
  auto it = j.find(key);
  if (it == j.end()) throw InputError(origin + ": " + where + " has no \"" + key + "\"");
  if constexpr (std::is_arithmetic_v<T>) {
    return numberAs<T>(*it, origin + ": " + where + " \"" + key + "\"");
  } else {
    try {
      return it->get<T>();
    } catch (const json::exception&) {
      throw InputError(origin + ": " + where + " \"" + key + "\" has the wrong type");
    }
  }
}

// Reads key from object j as T, or fallback when j has no such key.
template <class T>
T optionalField(const json& j, const char* key, T fallback, const std::string& origin, const std::string& where) {
  return j.contains(key) ? field<T>(j, key, origin, where) : fallback;
}

RunRecord parseRunRecord(const std::string& text, const std::string& origin);

}  // namespace

json farmJson(const FarmRecord& f) {
  json servers = json::array();
  for (const FarmServerRecord& s : f.servers) {
    json js = {{"rank", s.rank},
               {"pes", s.pes},
               {"prepareSeconds", s.prepareSeconds},
               {"prepareMessages", s.prepareMessages},
               {"prepareBytes", s.prepareBytes},
               {"busySeconds", s.busySeconds},
               {"idleSeconds", s.idleSeconds},
               {"jobs", s.jobs},
               {"lastHeardSeconds", s.lastHeardSeconds},
               {"lateResults", s.lateResults},
               {"cpuSeconds", s.cpuSeconds}};
    if (s.lost()) {
      js["lostAtSeconds"] = s.lostAtSeconds;
      js["handedOn"] = s.handedOn;
    }
    servers.push_back(js);
  }
  json jobs = json::array();
  for (const FarmJobRecord& j : f.jobs)
    jobs.push_back({j.job, j.server, j.sentSeconds, j.doneSeconds, j.busySeconds, j.attempts, j.resultBytes});
  return {{"schedule", f.schedule},     {"prepass", f.prepass}, {"deadlineSeconds", f.deadlineSeconds}, {"jobsAhead", f.jobsAhead},
          {"jobShape", f.jobShape},     {"wallSeconds", f.wallSeconds},         {"servers", servers},
          {"jobs", jobs}};  // jobs: [job, server, sentSeconds, doneSeconds, busySeconds, attempts, resultBytes]
}

std::string toJsonText(const RunRecord& record) { return toJson(record).dump(1) + "\n"; }

void writeRunRecord(const RunRecord& record, const std::filesystem::path& file) {
  writeText(toJsonText(record), file, "metrics");
}

RunRecord runRecordFromJsonText(const std::string& text, const std::string& origin) {
  try {
    return parseRunRecord(text, origin);
  } catch (const json::exception& e) {  // a value of the wrong type deep inside the record
    throw InputError(origin + ": malformed run record (" + e.what() + ")");
  }
}

namespace {

std::vector<int> intList(const json& j, const char* key, const std::string& origin, const std::string& where) {
  const json v = j.value(key, json::array());
  if (!v.is_array()) throw InputError(origin + ": " + where + " \"" + key + "\" must be an array");
  std::vector<int> out;
  for (const json& x : v) out.push_back(numberAs<int>(x, origin + ": " + where + " \"" + key + "\""));
  return out;
}

FarmRecord parseFarm(const json& jf, const std::string& origin) {
  const std::string where = "farm";
  if (!jf.is_object()) throw InputError(origin + ": \"farm\" must be an object");
  FarmRecord f;
  f.schedule = jf.value("schedule", std::string());
  f.prepass = jf.value("prepass", std::string("replicated"));
  f.deadlineSeconds = optionalField(jf, "deadlineSeconds", 0.0, origin, where);
  f.jobsAhead = optionalField(jf, "jobsAhead", 1, origin, where);
  f.jobShape = jf.value("jobShape", std::string());
  f.wallSeconds = optionalField(jf, "wallSeconds", 0.0, origin, where);
  for (const json& js : jf.value("servers", json::array())) {
    const std::string server = where + " server " + std::to_string(f.servers.size());
    FarmServerRecord s;
    s.rank = field<int>(js, "rank", origin, server);
    s.pes = optionalField(js, "pes", 1, origin, server);
    s.prepareSeconds = optionalField(js, "prepareSeconds", 0.0, origin, server);
    s.prepareMessages = optionalField(js, "prepareMessages", std::uint64_t{0}, origin, server);
    s.prepareBytes = optionalField(js, "prepareBytes", std::uint64_t{0}, origin, server);
    s.busySeconds = optionalField(js, "busySeconds", 0.0, origin, server);
    s.idleSeconds = optionalField(js, "idleSeconds", 0.0, origin, server);
    s.jobs = intList(js, "jobs", origin, server);
    s.lastHeardSeconds = optionalField(js, "lastHeardSeconds", 0.0, origin, server);
    s.lateResults = optionalField(js, "lateResults", 0, origin, server);
    s.cpuSeconds = optionalField(js, "cpuSeconds", 0.0, origin, server);
    s.lostAtSeconds = optionalField(js, "lostAtSeconds", -1.0, origin, server);
    s.handedOn = intList(js, "handedOn", origin, server);
    f.servers.push_back(std::move(s));
  }
  for (const json& jj : jf.value("jobs", json::array())) {
    if (!jj.is_array() || jj.size() != 7)
      throw InputError(origin + ": a farm job must be [job, server, sentSeconds, doneSeconds, busySeconds, attempts, resultBytes]");
    const std::string job = origin + ": farm job " + std::to_string(f.jobs.size());
    FarmJobRecord r;
    r.job = numberAs<int>(jj[0], job);
    r.server = numberAs<int>(jj[1], job + " server");
    r.sentSeconds = numberAs<double>(jj[2], job + " sentSeconds");
    r.doneSeconds = numberAs<double>(jj[3], job + " doneSeconds");
    r.busySeconds = numberAs<double>(jj[4], job + " busySeconds");
    r.attempts = numberAs<int>(jj[5], job + " attempts");
    r.resultBytes = numberAs<std::size_t>(jj[6], job + " resultBytes");
    f.jobs.push_back(r);
  }
  return f;
}

RunRecord parseRunRecord(const std::string& text, const std::string& origin) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::parse_error& e) {
    throw InputError(origin + ": not valid JSON (" + e.what() + ")");
  }
  if (!j.is_object()) throw InputError(origin + ": expected a run record (a JSON object)");
  const std::string top = "run record";
  RunRecord record;
  record.pes = field<int>(j, "pes", origin, top);
  if (record.pes < 1) throw InputError(origin + ": \"pes\" must be at least 1");
  record.ranks = optionalField(j, "ranks", 1, origin, top);
  if (record.ranks < 1 || record.pes % record.ranks != 0)
    throw InputError(origin + ": \"ranks\" must divide \"pes\" (" + std::to_string(record.pes) + ")");
  record.schedule = j.value("schedule", std::string());
  record.grain = optionalField(j, "grain", 1, origin, top);
  record.wallSeconds = optionalField(j, "wallSeconds", 0.0, origin, top);
  record.error = j.value("error", std::string());
  const json stages = field<json>(j, "stages", origin, top);
  if (!stages.is_array()) throw InputError(origin + ": \"stages\" must be an array");
  for (std::size_t i = 0; i < stages.size(); ++i) {
    const json& js = stages[i];
    const std::string where = "stage " + std::to_string(i);
    StageRecord s;
    s.name = field<std::string>(js, "name", origin, where);
    s.schedule = js.value("schedule", std::string());
    s.grain = optionalField(js, "grain", 1, origin, where);
    s.startSeconds = optionalField(js, "startSeconds", 0.0, origin, where);
    s.wallSeconds = field<double>(js, "wallSeconds", origin, where);
    s.broadcasts = optionalField(js, "broadcasts", std::uint64_t{0}, origin, where);
    s.broadcastBytes = optionalField(js, "broadcastBytes", std::uint64_t{0}, origin, where);
    for (const json& jp : js.value("pes", json::array())) {
      const std::string pe = where + " PE " + std::to_string(s.pes.size());
      const auto seconds = [&](const char* key) { return optionalField(jp, key, 0.0, origin, pe); };
      const auto count = [&](const char* key) { return optionalField(jp, key, std::uint64_t{0}, origin, pe); };
      PeStageRecord r;
      r.busySeconds = seconds("busySeconds");
      r.idleSeconds = seconds("idleSeconds");
      r.syncWaitSeconds = seconds("syncWaitSeconds");
      r.sendReceiveSeconds = seconds("sendReceiveSeconds");
      r.messageWaitSeconds = seconds("messageWaitSeconds");
      r.tasks = count("tasks");
      r.messagesHandled = count("messagesHandled");
      r.messagesSent = count("messagesSent");
      r.bytesSent = count("bytesSent");
      r.messagesReceived = count("messagesReceived");
      r.bytesReceived = count("bytesReceived");
      r.schedulingMessages = count("schedulingMessages");
      r.schedulingBytes = count("schedulingBytes");
      r.schedulingMessagesBetweenRanks = count("schedulingMessagesBetweenRanks");
      r.schedulingBytesBetweenRanks = count("schedulingBytesBetweenRanks");
      r.broadcastsReceived = count("broadcastsReceived");
      r.broadcastBytesReceived = count("broadcastBytesReceived");
      r.replicatedCopies = count("replicatedCopies");
      r.replicatedBytes = count("replicatedBytes");
      r.cacheHits = count("cacheHits");
      r.cacheMisses = count("cacheMisses");
      r.prefetches = count("prefetches");
      s.pes.push_back(r);
    }
    for (const json& jt : js.value("traffic", json::array())) {
      const std::string link = where + " traffic";
      s.traffic.push_back({optionalField(jt, "from", 0, origin, link), optionalField(jt, "to", 0, origin, link),
                           optionalField(jt, "messages", std::uint64_t{0}, origin, link),
                           optionalField(jt, "bytes", std::uint64_t{0}, origin, link)});
    }
    for (const json& jc : js.value("channels", json::array())) {
      const std::string channel = where + " channel";
      s.channels.push_back({jc.value("name", std::string()), jc.value("kind", std::string()),
                            optionalField(jc, "messages", std::uint64_t{0}, origin, channel),
                            optionalField(jc, "bytes", std::uint64_t{0}, origin, channel),
                            optionalField(jc, "betweenRankMessages", std::uint64_t{0}, origin, channel),
                            optionalField(jc, "betweenRankBytes", std::uint64_t{0}, origin, channel)});
    }
    const json tasks = field<json>(js, "tasks", origin, where);
    for (const json& jt : tasks) {
      if (!jt.is_array() || jt.size() != 3)
        throw InputError(origin + ": " + where + " \"tasks\" entries must be [costEstimate, x, y]");
      const std::string task = origin + ": " + where + " task";
      s.tasks.push_back({numberAs<double>(jt[0], task + " costEstimate"), numberAs<float>(jt[1], task + " x"),
                         numberAs<float>(jt[2], task + " y")});
    }
    const json preferred = js.value("preferred", json::array());
    if (!preferred.empty() && preferred.size() != s.tasks.size())
      throw InputError(origin + ": " + where + " \"preferred\" must name one PE (or -1) per task");
    for (std::size_t t = 0; t < preferred.size(); ++t) {
      const int pe = numberAs<int>(preferred[t], origin + ": " + where + " preferred PE");
      if (pe < -1 || pe >= record.pes)
        throw InputError(origin + ": " + where + " preferred PE " + std::to_string(pe) + " is not -1 or one of the " +
                         std::to_string(record.pes) + " PEs");
      s.tasks[t].preferredPe = pe;
    }
    for (const json& owner : js.value("owners", json::array()))
      s.owners.push_back(numberAs<int>(owner, origin + ": " + where + " owner"));
    if (!s.owners.empty() && s.owners.size() != s.tasks.size())
      throw InputError(origin + ": " + where + " \"owners\" must name one PE per task");
    s.kind = js.value("kind", std::string());  // optional: records written before stages had kinds
    if (!s.kind.empty() && s.kind != kEachPeStage && s.kind != kOnePeStage && s.kind != kEachPeInFullStage)
      throw InputError(origin + ": " + where + " \"kind\" must be \"" + kEachPeStage + "\", \"" + kEachPeInFullStage + "\" or \"" +
                       kOnePeStage + "\", not \"" + s.kind + "\"");
    s.cellSplit = js.value("cellSplit", std::string());  // optional: only stages made of cells
    if (!s.cellSplit.empty() && !isCellSplit(s.cellSplit))
      throw InputError(origin + ": " + where + " \"cellSplit\" must be \"" + kRoundRobinCells + "\" or \"" + kStripCells +
                       "\", not \"" + s.cellSplit + "\"");
    if (!s.cellSplit.empty()) {
      s.cellCount = numberAs<int>(field<json>(js, "cellCount", origin, where), origin + ": " + where + " cellCount");
      if (s.cellCount < 1) throw InputError(origin + ": " + where + " \"cellCount\" must be at least 1");
      s.cellCollector = numberAs<int>(field<json>(js, "cellCollector", origin, where), origin + ": " + where + " cellCollector");
      if (s.cellCollector < -1 || s.cellCollector >= record.pes)
        throw InputError(origin + ": " + where + " \"cellCollector\" must be -1 or one of the " + std::to_string(record.pes) +
                         " PEs");
    }
    record.stages.push_back(std::move(s));
  }
  const json timeline = field<json>(j, "timeline", origin, top);
  for (const json& jt : timeline) {
    // Records written before spans carried their waiting have seven fields.
    if (!jt.is_array() || (jt.size() != 7 && jt.size() != 8))
      throw InputError(origin +
                       ": \"timeline\" entries must be [pe, stage, task, start, end, messagesSent, bytesSent, waitSeconds]");
    const std::string spanWhat = origin + ": timeline span";
    TaskSpan span{numberAs<int>(jt[0], spanWhat + " pe"),           numberAs<int>(jt[1], spanWhat + " stage"),
                  numberAs<TaskId>(jt[2], spanWhat + " task"),      numberAs<double>(jt[3], spanWhat + " start"),
                  numberAs<double>(jt[4], spanWhat + " end"),       numberAs<std::uint32_t>(jt[5], spanWhat + " messagesSent"),
                  numberAs<std::uint64_t>(jt[6], spanWhat + " bytesSent"),
                  jt.size() == 8 ? numberAs<double>(jt[7], spanWhat + " waitSeconds") : 0.0};
    if (!(span.waitSeconds >= 0.0) || span.waitSeconds > span.end - span.start + 1e-9)
      throw InputError(origin + ": a \"timeline\" span waits longer than it lasts");
    if (span.stage < 0 || span.stage >= static_cast<int>(record.stages.size()) || span.pe < 0 ||
        span.pe >= record.pes || span.task < kSetupSpan ||
        span.task >= static_cast<TaskId>(record.stages[span.stage].tasks.size()))
      throw InputError(origin + ": \"timeline\" span names a PE, stage or task the record does not have");
    record.timeline.push_back(span);
  }
  // Optional: only runs with stages made of cells have them.
  for (const json& jc : j.value("cells", json::array())) {
    if (!jc.is_array() || jc.size() != 5) throw InputError(origin + ": \"cells\" entries must be [pe, stage, cell, seconds, resultBytes]");
    const std::string what = origin + ": cell";
    const CellSpan c{numberAs<int>(jc[0], what + " pe"), numberAs<int>(jc[1], what + " stage"), numberAs<int>(jc[2], what + " cell"),
                     numberAs<double>(jc[3], what + " seconds"), numberAs<std::uint64_t>(jc[4], what + " resultBytes")};
    if (c.stage < 0 || c.stage >= static_cast<int>(record.stages.size()) || record.stages[c.stage].cellSplit.empty() ||
        c.pe < 0 || c.pe >= record.pes || c.cell < kCollectCell || c.cell >= record.stages[c.stage].cellCount ||
        !(c.seconds >= 0.0))
      throw InputError(origin + ": a \"cells\" entry names a PE, stage or cell the record does not have, or a negative time");
    if (c.cell == kCollectCell && c.pe != record.stages[c.stage].cellCollector)
      throw InputError(origin + ": a \"cells\" entry of the collector's storing is on PE " + std::to_string(c.pe) +
                       ", not the stage's collector");
    record.cells.push_back(c);
  }
  // Optional: records written before counters existed have none.
  for (const json& jc : j.value("counters", json::array())) {
    CounterRecord c;
    c.name = field<std::string>(jc, "name", origin, "counter");
    for (const json& v : field<json>(jc, "perPe", origin, "counter " + c.name))
      c.perPe.push_back(numberAs<double>(v, origin + ": counter " + c.name + " value"));
    if (static_cast<int>(c.perPe.size()) != record.pes)
      throw InputError(origin + ": counter \"" + c.name + "\" needs one value per PE (" + std::to_string(record.pes) + ")");
    record.counters.push_back(std::move(c));
  }
  if (j.contains("farm")) record.farm = parseFarm(j["farm"], origin);
  return record;
}

}  // namespace

RunRecord readRunRecord(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError("cannot read metrics file '" + file.string() + "'");
  std::stringstream text;
  text << in.rdbuf();
  return runRecordFromJsonText(text.str(), "metrics file '" + file.string() + "'");
}

std::string toChromeTraceText(const RunRecord& record) {
  json events = json::array();
  for (int p = 0; p < record.pes; ++p)
    events.push_back({{"name", "thread_name"}, {"ph", "M"}, {"pid", 0}, {"tid", p},
                      {"args", {{"name", "PE " + std::to_string(p)}}}});
  for (const TaskSpan& t : record.timeline) {
    const std::string stage = t.stage < static_cast<int>(record.stages.size()) ? record.stages[t.stage].name : "?";
    const std::string name = t.task == kMessageSpan ? "message" : t.task == kSetupSpan ? "set-up" : "task " + std::to_string(t.task);
    events.push_back({{"name", name},
                      {"cat", stage},
                      {"ph", "X"},
                      {"pid", 0},
                      {"tid", t.pe},
                      {"ts", t.start * 1e6},  // microseconds, as the format requires
                      {"dur", (t.end - t.start) * 1e6},
                      {"args",
                       {{"stage", stage},
                        {"task", t.task},
                        {"messagesSent", t.messagesSent},
                        {"bytesSent", t.bytesSent},
                        {"waitSeconds", t.waitSeconds}}}});
  }
  json j = {{"traceEvents", events}, {"displayTimeUnit", "ms"}};
  return j.dump() + "\n";
}

void writeChromeTrace(const RunRecord& record, const std::filesystem::path& file) {
  writeText(toChromeTraceText(record), file, "trace");
}

}  // namespace pr::par
