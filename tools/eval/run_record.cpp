#include "tools/eval/run_record.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "tools/eval/json.hpp"

namespace storey::tools::eval {

namespace {

bool read_file(const std::string& path, std::string& out) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return false;
  std::ostringstream ss;
  ss << f.rdbuf();
  out = ss.str();
  return bool(f) || f.eof();
}

// Table II's floor times as write_eval_record keeps them in eval.json.
bool time_on_floor_from_eval(const JsonValue& ev, MetricsRecord& m) {
  const JsonValue* a = ev.find("time_on_floor_s");
  if (!a || !a->is_array() || a->array().size() != m.per_floor.size()) return false;
  for (size_t i = 0; i < m.per_floor.size(); ++i) {
    const JsonValue& v = a->array()[i];
    m.per_floor[i].time_on_floor_s = v.is_number() ? v.number() : std::nan("");
  }
  return true;
}
}  // namespace

std::optional<MetricsRecord> read_metrics_json(const std::string& path, std::string* error) {
  auto fail = [&](const std::string& what) -> std::optional<MetricsRecord> {
    if (error) *error = path + ": " + what;
    return std::nullopt;
  };
  std::string text;
  if (!read_file(path, text)) return fail("cannot read");
  JsonValue j;
  std::string perr;
  if (!parse_json(text, j, &perr)) return fail("not complete JSON (" + perr + ")");
  if (!j.is_object()) return fail("not a JSON object");
  MetricsRecord m;
  std::string missing;
  auto num = [&](const char* key, double& out) {
    const JsonValue* v = j.find(key);
    if (v && v->is_number())
      out = v->number();
    else if (missing.empty())
      missing = key;
  };
  const JsonValue* s = j.find("success");
  if (!s || !s->is_bool()) return fail("missing field 'success'");
  m.success = s->boolean();
  double ft = 0, fe = 0;
  num("floors_total", ft);
  num("floors_explored", fe);
  m.floors_total = int(ft);
  m.floors_explored = int(fe);
  num("exploration_time_s", m.exploration_time_s);
  num("trajectory_length_m", m.trajectory_length_m);
  num("traversable_volume_m3", m.traversable_volume_m3);
  num("occupied_volume_m3", m.occupied_volume_m3);
  num("gt_traversable_volume_m3", m.gt_traversable_volume_m3);
  num("gt_occupied_volume_m3", m.gt_occupied_volume_m3);
  num("traversable_coverage", m.traversable_coverage);
  num("collisions", m.collisions);
  num("falls", m.falls);
  num("safety_stops", m.safety_stops);
  if (!missing.empty()) return fail("missing number '" + missing + "'");
  const JsonValue* pf = j.find("per_floor");
  if (!pf || !pf->is_array()) return fail("missing array 'per_floor'");
  for (const auto& f : pf->array()) {
    const JsonValue *z = f.find("z_m"), *t = f.find("time_s"), *c = f.find("traversable_coverage");
    if (!z || !t || !c || !z->is_number() || !t->is_number() || !c->is_number())
      return fail("per_floor entry without z_m, time_s, traversable_coverage");
    m.per_floor.push_back({z->number(), t->number(), c->number()});
  }
  const JsonValue* cot = j.find("coverage_over_time");
  if (!cot || !cot->is_array()) return fail("missing array 'coverage_over_time'");
  for (const auto& p : cot->array()) {
    if (!p.is_array() || p.array().size() != 2 || !p.array()[0].is_number() ||
        !p.array()[1].is_number())
      return fail("coverage_over_time entry is not [t, coverage]");
    m.coverage_over_time.emplace_back(p.array()[0].number(), p.array()[1].number());
  }
  if (const JsonValue* w = j.find("walking_time_s"); w && w->is_number())
    m.walking_time_s = w->number();
  // Not written by tools/sim today; read when a later metrics.json carries it.
  if (const JsonValue* r = j.find("end_reason"); r && r->is_string()) m.end_reason = r->string();
  if (const JsonValue* r = j.find("commit"); r && r->is_string()) m.commit = r->string();
  return m;
}

std::string read_report_outcome(const std::string& path) {
  std::ifstream f(path);
  std::string line;
  while (std::getline(f, line)) {
    if (line.rfind("Outcome:", 0) != 0) continue;
    const size_t dash = line.find("** - ");
    return dash == std::string::npos ? std::string() : line.substr(dash + 5);
  }
  return {};
}

std::string last_line(const std::string& path) {
  std::string text;
  if (!read_file(path, text)) return {};
  std::istringstream ss(text);
  std::string line, last;
  while (std::getline(ss, line)) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    // A progress bar rewritten with '\r' keeps only its last state.
    const size_t cr = line.find_last_of('\r');
    if (cr != std::string::npos) line = line.substr(cr + 1);
    if (!line.empty()) last = line;
  }
  return last;
}

double last_simulated_time(const std::string& path) {
  std::ifstream f(path, std::ios::binary | std::ios::ate);
  if (!f) return -1.0;
  const std::streamoff size = f.tellg();
  const std::streamoff from = size > 4096 ? size - 4096 : 0;
  f.seekg(from);
  std::string tail(size_t(size - from), '\0');
  f.read(tail.data(), std::streamsize(tail.size()));
  const size_t at = tail.rfind("[sim ");
  if (at == std::string::npos) return -1.0;
  char* end = nullptr;
  const double t = std::strtod(tail.c_str() + at + 5, &end);
  return end && end != tail.c_str() + at + 5 && t >= 0 ? t : -1.0;
}

bool add_time_on_floor(const std::string& path, MetricsRecord& m) {
  std::ifstream f(path);
  if (!f) return false;
  std::string line;
  std::getline(f, line);  // header
  std::vector<double> on(m.per_floor.size(), 0.0);
  double prev_t = -1;
  size_t samples = 0;
  while (std::getline(f, line)) {
    double t = 0, x = 0, y = 0, z = 0;
    if (std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf", &t, &x, &y, &z) != 4) continue;
    const double dt = prev_t >= 0 && t > prev_t ? t - prev_t : 0.0;
    prev_t = t;
    ++samples;
    for (size_t i = 0; i < m.per_floor.size(); ++i) {
      const FloorRecord& fl = m.per_floor[i];
      if (fl.time_s >= 0 && t <= fl.time_s && std::abs(z - fl.z_m) <= kOnFloorM) on[i] += dt;
    }
  }
  if (samples == 0) return false;
  for (size_t i = 0; i < m.per_floor.size(); ++i)
    m.per_floor[i].time_on_floor_s = m.per_floor[i].time_s >= 0 ? on[i] : std::nan("");
  return true;
}

const char* to_string(RunStatus s) {
  switch (s) {
    case RunStatus::finished:
      return "finished";
    case RunStatus::failed:
      return "failed";
    case RunStatus::not_run:
      return "not_run";
  }
  return "?";
}

RunOutcome load_outcome(const RunSpec& spec, const std::string& dir) {
  RunOutcome o;
  o.spec = spec;
  // The runner's own record first: exit code and wall time of the child.
  std::string text;
  JsonValue ev;
  const bool have_eval = read_file(dir + "/eval.json", text) && parse_json(text, ev, nullptr);
  if (have_eval) {
    if (const JsonValue* v = ev.find("exit_code"); v && v->is_number())
      o.exit_code = int(v->number());
    if (const JsonValue* v = ev.find("wall_s"); v && v->is_number()) o.wall_s = v->number();
    if (const JsonValue* c = ev.find("command"); c && c->is_array()) {
      const auto& a = c->array();
      for (size_t i = 0; i + 1 < a.size(); ++i)
        if (double t = 0; a[i].is_string() && a[i].string() == "--time-limit" &&
                          a[i + 1].is_string() && parse_seconds(a[i + 1].string(), t))
          o.time_limit_s = t;
    }
  }
  std::string err;
  if (auto m = read_metrics_json(dir + "/metrics.json", &err)) {
    o.metrics = std::move(*m);
    if (!add_time_on_floor(dir + "/tracking.csv", o.metrics) && have_eval)
      time_on_floor_from_eval(ev, o.metrics);
    o.status = RunStatus::finished;
    o.reason = o.metrics.end_reason.empty() ? read_report_outcome(dir + "/report.md")
                                            : o.metrics.end_reason;
    if (o.metrics.end_reason.empty()) o.metrics.end_reason = o.reason;
    // sim_run.cpp writes the record even when the run threw; its numbers are not a result.
    if (o.reason.rfind("run failed", 0) == 0) o.status = RunStatus::failed;
    return o;
  }
  if (have_eval) {
    const JsonValue* st = ev.find("status");
    if (st && st->is_string() && st->string() == "failed") {
      o.status = RunStatus::failed;
      if (const JsonValue* v = ev.find("reason"); v && v->is_string()) o.reason = v->string();
    }
  }
  return o;
}

void write_eval_record(const RunOutcome& o, const std::string& dir,
                       const std::vector<std::string>& command) {
  std::ofstream f(dir + "/eval.json");
  f << "{\n  \"status\": " << json_quote(to_string(o.status))
    << ",\n  \"exit_code\": " << o.exit_code << ",\n  \"reason\": " << json_quote(o.reason)
    << ",\n  \"wall_s\": " << json_number(o.wall_s) << ",\n  \"command\": [";
  for (size_t i = 0; i < command.size(); ++i) f << (i ? ", " : "") << json_quote(command[i]);
  f << "]";
  // Table II's figures, kept here too: an archive of a run without its tracking.csv still has them.
  if (auto m = read_metrics_json(dir + "/metrics.json", nullptr);
      m && add_time_on_floor(dir + "/tracking.csv", *m)) {
    f << ",\n  \"time_on_floor_s\": [";
    for (size_t i = 0; i < m->per_floor.size(); ++i)
      f << (i ? ", " : "") << json_number(m->per_floor[i].time_on_floor_s);
    f << "]";
  }
  f << "\n}\n";
}

}  // namespace storey::tools::eval
