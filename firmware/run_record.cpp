#include "firmware/run_record.hpp"

#include <cinttypes>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "core/graph/graph_export.hpp"
#include "core/map/ply_export.hpp"

namespace storey::firmware {

namespace {

void add(std::string& s, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
void add(std::string& s, const char* fmt, ...) {
  char buf[512];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  s += buf;
}

std::string esc(const std::string& in) {
  std::string o;
  for (char c : in) {
    if (c == '"' || c == '\\') o += '\\';
    if (static_cast<unsigned char>(c) < 0x20) continue;
    o += c;
  }
  return o;
}

double ms(std::int64_t ns) {
  return double(ns) * 1e-6;
}

bool write_file(const std::string& path, const std::string& text, std::string* error) {
  std::ofstream f(path);
  f << text;
  f.close();
  if (!f && error && error->empty()) *error = path + ": cannot write";
  return bool(f);
}

}  // namespace

std::string latency_table_markdown(const std::vector<rt::TaskReport>& reports) {
  std::string s =
      "| task | rate [Hz] | budget [ms] | runs | p50 [ms] | p99 [ms] | max [ms] | jitter p99 "
      "[ms] | overruns | missed | p99 within budget |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const rt::TaskReport& r : reports) {
    char rate[16];
    if (r.rate_hz > 0)
      std::snprintf(rate, sizeof rate, "%g", r.rate_hz);
    else
      std::snprintf(rate, sizeof rate, "event");
    add(s,
        "| %s | %s | %.1f | %" PRIu64 " | %.3f | %.3f | %.3f | %.3f | %" PRIu64 " | %" PRIu64
        " | %s |\n",
        r.name.c_str(), rate, double(r.budget_us) * 1e-3, r.runs, ms(r.exec.p50_ns),
        ms(r.exec.p99_ns), ms(r.exec.max_ns), r.rate_hz > 0 ? ms(r.jitter.p99_ns) : 0.0, r.overruns,
        r.missed,
        r.budget_us <= 0 ? "-" : (r.exec.p99_ns <= r.budget_us * 1000 ? "yes" : "**no**"));
  }
  return s;
}

std::vector<std::string> write_live_record(const std::string& dir, Autonomy& autonomy,
                                           LivePlatform& platform, const LiveRunSummary& m,
                                           std::string* error) {
  namespace fs = std::filesystem;
  std::vector<std::string> written;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) {
    if (error) *error = dir + ": " + ec.message();
    return written;
  }
  const auto reports = autonomy.scheduler().reports();
  const auto& map = autonomy.map_for_record();
  const double res = map.options().voxel_size_m;
  uint64_t trav = 0, occ = 0;
  map.view().for_each_occupied([&](const core::map::VoxelKey&, const core::map::Cell& c, auto*) {
    ++occ;
    if (c.state == core::map::TravState::kTraversable) ++trav;
  });
  const auto world = autonomy.world();
  const ExplorationStatus st = autonomy.status();
  const auto lc = platform.lidar_counters();
  const LiveCounters pc = platform.counters();
  const drivers::go2::LinkHealth lh = platform.link_health();

  // metrics.json: DESIGN §7 keys that are defined live (no ground truth: no coverage, no floors
  // total, no collisions or falls: the robot does not report them), plus the live counters.
  std::string j = "{\n";
  add(j, "  \"mode\": \"run\",\n  \"success\": %s,\n  \"end_reason\": \"%s\",\n",
      m.completed ? "true" : "false", esc(m.end_reason).c_str());
  add(j, "  \"exploration_time_s\": %.3f,\n  \"trajectory_length_m\": %.3f,\n", m.run_time_s,
      m.trajectory_length_m);
  add(j, "  \"traversable_volume_m3\": %.4f,\n  \"occupied_volume_m3\": %.4f,\n",
      double(trav) * res * res * res, double(occ) * res * res * res);
  j += "  \"floors_visited\": [";
  for (size_t i = 0; i < m.floors_visited.size(); ++i)
    add(j, "%s%d", i ? ", " : "", m.floors_visited[i]);
  add(j,
      "],\n  \"graph\": {\"nodes\": %u, \"edges\": %u, \"frontier_nodes\": %u, \"clusters\": %u, "
      "\"trajectories\": %" PRIu64 "},\n",
      st.nodes, st.edges, st.frontier_nodes, st.clusters, st.trajectories);
  // safety_stops: stops during the run; stop_reasons also counts the shutdown's operator stop.
  add(j, "  \"safety_stops\": %" PRIu64 ",\n  \"stop_reasons\": {", m.safety_stops);
  for (int r = 0; r < int(StopReason::kCount); ++r)
    add(j, "%s\"%s\": %" PRIu64, r ? ", " : "", to_string(StopReason(r)),
        autonomy.stop_events(StopReason(r)));
  j += "},\n  \"latency\": {";
  for (size_t i = 0; i < reports.size(); ++i) {
    const auto& r = reports[i];
    add(j,
        "%s\n    \"%s\": {\"p50_ms\": %.3f, \"p99_ms\": %.3f, \"max_ms\": %.3f, \"overruns\": "
        "%" PRIu64 ", \"budget_ms\": %.3f, \"runs\": %" PRIu64 ", \"missed\": %" PRIu64
        ", \"jitter_p99_ms\": %.3f}",
        i ? "," : "", r.name.c_str(), ms(r.exec.p50_ns), ms(r.exec.p99_ns), ms(r.exec.max_ns),
        r.overruns, double(r.budget_us) * 1e-3, r.runs, r.missed,
        r.rate_hz > 0 ? ms(r.jitter.p99_ns) : 0.0);
  }
  uint64_t dropped = 0;
  for (size_t i = 1; i < lc.drops.size(); ++i) dropped += lc.drops[i];
  add(j,
      "\n  },\n  \"lidar\": {\"datagrams\": %" PRIu64 ", \"accepted\": %" PRIu64
      ", \"points\": %" PRIu64 ", \"scans\": %" PRIu64 ", \"scans_without_pose\": %" PRIu64
      ", \"scans_dropped_map_behind\": %" PRIu64 ", \"points_out_of_range\": %" PRIu64
      ", \"points_without_pose\": %" PRIu64 ", \"lost_udp_cnt\": %" PRIu64
      ", \"record_dropped\": %" PRIu64 ", \"dropped\": %" PRIu64 ", \"drops\": {",
      lc.datagrams, lc.accepted, lc.points, pc.scans, pc.scans_without_pose,
      autonomy.scans_dropped(), pc.points_out_of_range, pc.points_without_pose, lc.lost_udp_cnt,
      lc.record_dropped, dropped);
  for (size_t i = 1; i < lc.drops.size(); ++i)
    add(j, "%s\"%s\": %" PRIu64, i > 1 ? ", " : "",
        drivers::lidar::to_string(drivers::lidar::DropReason(i)), lc.drops[i]);
  add(j,
      "}},\n  \"link\": {\"states\": %" PRIu64 ", \"frozen_states\": %" PRIu64
      ", \"commands_sent\": %" PRIu64 ", \"commands_refused\": %" PRIu64
      ", \"link_lost_events\": %" PRIu64 ", \"reconnects\": %" PRIu64
      ", \"sequence_gaps\": %" PRIu64 ", \"crc_failures\": %" PRIu64 ", \"decode_errors\": %" PRIu64
      ", \"stale_commands_refused\": %" PRIu64 ", \"send_errors\": %" PRIu64 "},\n",
      pc.states, pc.frozen_states, pc.commands_sent, pc.commands_refused, lh.link_lost_events,
      lh.reconnects, lh.sequence_gaps, lh.crc_failures, lh.decode_errors, lh.stale_commands_refused,
      lh.send_errors);
  add(j, "  \"record\": {\"file\": \"%s\", \"datagrams\": %" PRIu64 "}\n}\n",
      esc(m.record_path).c_str(), m.record_written);
  if (write_file(dir + "/metrics.json", j, error)) written.push_back("metrics.json");

  const std::string table = latency_table_markdown(reports);
  if (write_file(dir + "/latency.md",
                 "# Per-task latency (storey run: real-time threads, monotonic clock)\n\n" + table +
                     "\n```\n" + autonomy.scheduler().report() + "```\n",
                 error))
    written.push_back("latency.md");
  std::string err;
  if (autonomy.trace().write_chrome_json(dir + "/trace.json", &err))
    written.push_back("trace.json");
  else if (error && error->empty())
    *error = err;
  if (core::map::write_ply_occupied(map.view(), dir + "/map.ply").ok) written.push_back("map.ply");
  if (world && core::graph::write_text_file(
                   dir + "/graph.json",
                   core::graph::to_json(world->graph, &world->clusters, &world->viewpoints), &err))
    written.push_back("graph.json");

  std::string r = "# storey run\n\n";
  add(r, "Command: `%s`\n\nConfiguration: `%s`\n\nOutcome: **%s** - %s\n\n", m.command.c_str(),
      m.config.c_str(), m.completed ? "exploration complete" : "stopped", m.end_reason.c_str());
  add(r,
      "| metric | value |\n|---|---|\n| run time | %.1f s |\n| trajectory length | %.1f m |\n"
      "| traversable / occupied volume | %.2f / %.2f m^3 |\n| graph nodes / frontier nodes | %u / "
      "%u |\n| safety stops | %" PRIu64 " |\n| LiDAR datagrams / dropped | %" PRIu64 " / %" PRIu64
      " |\n| scans | %" PRIu64 " |\n\n",
      m.run_time_s, m.trajectory_length_m, double(trav) * res * res * res,
      double(occ) * res * res * res, st.nodes, st.frontier_nodes, autonomy.safety_stops(),
      lc.datagrams, dropped, pc.scans);
  r += "## Latency per task\n\n" + table +
       "\nTrace: [trace.json](trace.json) (open in https://ui.perfetto.dev).\n\n## Files\n\n";
  for (const auto& w : written) r += "- [" + w + "](" + w + ")\n";
  if (!m.warnings.empty()) {
    r += "\n## Warnings\n\n";
    for (const auto& w : m.warnings) r += "- " + w + "\n";
  }
  if (!m.log.empty()) {
    r += "\n## Firmware log\n\n```\n";
    for (const auto& l : m.log) r += l + "\n";
    r += "```\n";
  }
  if (write_file(dir + "/report.md", r, error)) written.push_back("report.md");
  return written;
}

}  // namespace storey::firmware
