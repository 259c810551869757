// storey run --config FILE: live on the robot, or hardware-in-the-loop against `storey-sim
// --config` (DESIGN §1, §7). The task table of autonomy.cpp on real-time threads
// (Scheduler::start: SCHED_FIFO, mlockall, CPU pinning from the config's `realtime` section,
// each degrading with one warning) over the LivePlatform (LiDAR UDP + robot link). The main
// thread only watches: progress every second, SIGINT/SIGTERM, --duration, exploration complete.
// Shutdown commands a stop first (operator stop -> zero velocity within one control period), then
// stops the tasks, sends zero + StopMove on the link, prints the latency table and writes the
// run record. --record FILE.pcap: the receiver's raw datagram tap drained by a non-RT thread into
// a PcapWriter.
#include <signal.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "config/parameters.hpp"
#include "drivers/pcap/pcap_reader.hpp"
#include "firmware/autonomy.hpp"
#include "firmware/commands.hpp"
#include "firmware/link_factory.hpp"
#include "firmware/live_platform.hpp"
#include "firmware/run_record.hpp"
#include "rt/clock.hpp"

namespace storey::firmware {

namespace {

std::atomic<int> g_signal{0};
extern "C" void on_stop_signal(int sig) {
  g_signal.store(sig);
}

void print_help(FILE* out) {
  std::fprintf(
      out,
      "usage: storey run --config FILE [--record FILE.pcap] [--duration S] [--out DIR]\n\n"
      "Live exploration: LiDAR packets over UDP (sensor.*), the robot over its link (link.*:\n"
      "dds, udp or can), the task table on real-time threads (realtime.*: SCHED_FIFO, mlockall,\n"
      "CPU pinning; each degrades with one warning when not permitted). Against `storey-sim\n"
      "--scene NAME --config FILE` the same command is hardware-in-the-loop.\n"
      "Progress every second on stderr. Ends on Ctrl-C / SIGTERM, after --duration, or when\n"
      "exploration is complete: a commanded stop first, then the per-task latency table\n"
      "(p50/p99/max, overruns) and the run record in DIR: metrics.json, latency.md,\n"
      "trace.json, map.ply, graph.json, report.md.\n\n"
      "  --config FILE     configuration (required; check it with storey check-config)\n"
      "  --record FILE     also write every accepted LiDAR datagram to FILE (pcap)\n"
      "  --duration S      stop after S seconds of wall time (default: run until stopped)\n"
      "  --out DIR         run record folder (default out/run)\n"
      "Exit status: 0 ok, 1 the run failed (socket, link, record), 2 bad usage or config.\n");
}

// Non-RT thread: the raw datagram tap into a pcap file.
class Recorder {
 public:
  Recorder(rt::SpscQueue<drivers::lidar::RawDatagram>& q, drivers::pcap::PcapWriter& w)
      : q_(q), w_(w), thread_([this] { loop(); }) {}
  ~Recorder() { stop(); }
  void stop() {
    if (!thread_.joinable()) return;
    stop_.store(true);
    thread_.join();
    drain();
    w_.flush();
  }
  uint64_t written() const { return written_.load(); }

 private:
  void drain() {
    while (drivers::lidar::RawDatagram* r = q_.front()) {
      drivers::pcap::UdpDatagram d;
      d.timestamp_ns = r->receive_time_ns;
      d.src_addr = r->src_addr;
      d.dst_addr = r->dst_addr;
      d.src_port = r->src_port;
      d.dst_port = r->dst_port;
      d.payload = {r->data.data(), r->size};
      if (w_.write(d)) written_.fetch_add(1);
      q_.pop();
    }
  }
  void loop() {
    while (!stop_.load()) {
      drain();
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  rt::SpscQueue<drivers::lidar::RawDatagram>& q_;
  drivers::pcap::PcapWriter& w_;
  std::atomic<bool> stop_{false};
  std::atomic<uint64_t> written_{0};
  std::thread thread_;
};

std::string mask_names(uint32_t mask) {
  if (mask == 0) return "none";
  std::string s;
  for (int r = 0; r < int(StopReason::kCount); ++r)
    if (mask & (1u << r)) s += (s.empty() ? "" : ",") + std::string(to_string(StopReason(r)));
  return s;
}

}  // namespace

int cmd_run(int argc, char** argv) {
  std::string config_path, record_path, out_dir = "out/run";
  double duration_s = 0;
  std::string command = "storey run";
  for (int i = 0; i < argc; ++i)
    if (i > 0) command += std::string(" ") + argv[i];
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](const char* flag) -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "storey run: %s needs a value\n", flag);
        return nullptr;
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      print_help(stdout);
      return 0;
    } else if (a == "--config") {
      const char* v = value("--config");
      if (!v) return 2;
      config_path = v;
    } else if (a == "--record") {
      const char* v = value("--record");
      if (!v) return 2;
      record_path = v;
    } else if (a == "--out") {
      const char* v = value("--out");
      if (!v) return 2;
      out_dir = v;
    } else if (a == "--duration") {
      const char* v = value("--duration");
      if (!v) return 2;
      char* end = nullptr;
      duration_s = std::strtod(v, &end);
      if (end == v || *end != '\0' || !(duration_s > 0) || !std::isfinite(duration_s)) {
        std::fprintf(stderr, "storey run: --duration '%s' must be a number of seconds > 0\n", v);
        return 2;
      }
    } else {
      std::fprintf(stderr, "storey run: unknown argument '%s' (see --help)\n", a.c_str());
      return 2;
    }
  }
  if (config_path.empty()) {
    std::fprintf(stderr, "storey run: --config FILE is required (see --help)\n");
    return 2;
  }
  const config::Result cfg = config::load(config_path);
  if (!cfg.ok()) {
    std::fprintf(stderr, "storey run: %s (%zu error(s); see storey check-config %s)\n",
                 cfg.errors.front().to_string().c_str(), cfg.errors.size(), config_path.c_str());
    return 2;
  }
  const config::Parameters& params = cfg.params;
  LiveRunSummary summary;
  summary.command = command;
  summary.config = config_path;
  auto warn = [&](const std::string& w) {
    std::fprintf(stderr, "storey: warning: %s\n", w.c_str());
    summary.warnings.push_back(w);
  };

  rt::MonotonicClock clock;
  std::string err;
  auto link = make_robot_link(params, clock.now_ns(), &err);
  if (!link) {
    std::fprintf(stderr, "storey run: %s: %s\n", config_path.c_str(), err.c_str());
    return params.link.transport == config::LinkTransport::kSim ? 2 : 1;
  }
  const std::string link_name = link->name();
  LivePlatformOptions lo;
  lo.params = params;
  lo.record_queue = record_path.empty() ? 0 : 4096;  // ~5 s of VLP-16 datagrams
  LivePlatform platform(lo, std::move(link), clock);
  const auto open = platform.open();
  if (!open.ok) {
    std::fprintf(stderr, "storey run: %s\n", open.error.c_str());
    return 1;
  }
  if (!open.warning.empty()) warn(open.warning);  // e.g. rmem_max caps the receive buffer

  drivers::pcap::PcapWriter writer;
  std::unique_ptr<Recorder> recorder;
  if (!record_path.empty()) {
    if (!writer.open(record_path, &err)) {
      std::fprintf(stderr, "storey run: --record %s\n", err.c_str());
      return 2;
    }
    recorder = std::make_unique<Recorder>(*platform.record_queue(), writer);
    summary.record_path = record_path;
  }

  AutonomyOptions ao;
  ao.params = params;
  const bool mid360 = params.sensor.type == config::SensorType::kMid360;
  ao.fov = mid360 ? core::graph::SensorFov::mid360() : core::graph::SensorFov::vlp16();
  ao.fov.mount_height_m = params.sensor.mounting_xyz_m[2] + lo.default_body_height_m;
  ao.stop_on_overruns = true;
  ao.ingest_fd = platform.lidar_fd();
  ao.log = [&summary](const std::string& line) {  // telemetry task only; read after stop
    std::fprintf(stderr, "storey: %s\n", line.c_str());
    summary.log.push_back(line);
  };
  Autonomy autonomy(platform, clock, ao);

  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);

  std::fprintf(stderr, "storey run: %s, LiDAR %s on %s:%u from %s, link %s%s%s\n",
               config_path.c_str(), mid360 ? "mid360" : "vlp16", params.sensor.host_address.c_str(),
               unsigned(platform.lidar_port()),
               params.sensor.sensor_address.empty() ? "any" : params.sensor.sensor_address.c_str(),
               link_name.c_str(), record_path.empty() ? "" : ", recording to ",
               record_path.c_str());
  // Scheduler warnings (no SCHED_FIFO, no mlockall, no pinning) go through the default
  // "storey: warning:" line, one each.
  const rt::StartResult sr = autonomy.scheduler().start();
  if (!sr.ok) {
    std::fprintf(stderr, "storey run: %s\n", sr.error.c_str());
    return 1;
  }
  std::fprintf(stderr, "storey run: %zu tasks started (%d SCHED_FIFO, %d pinned, memory %s)\n",
               autonomy.scheduler().size(), sr.fifo_tasks, sr.pinned_tasks,
               sr.memory_locked ? "locked" : "not locked");

  const std::int64_t t0 = clock.now_ns();
  std::int64_t next_progress = t0 + 1'000'000'000;
  PoseSample last{};
  bool have_last = false;
  std::set<int> floors;
  for (;;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const std::int64_t now = clock.now_ns();
    const double t = double(now - t0) * 1e-9;
    PoseSample p;
    if (platform.read_pose(p)) {
      if (have_last) summary.trajectory_length_m += (p.position() - last.position()).norm();
      last = p;
      have_last = true;
    }
    const ExplorationStatus st = autonomy.status();
    if (st.stamp_s > 0) floors.insert(st.floor_hint);
    if (now >= next_progress) {
      next_progress += 1'000'000'000;
      const auto lc = platform.lidar_counters();
      const LiveCounters pc = platform.counters();
      uint64_t drops = 0;
      for (size_t i = 1; i < lc.drops.size(); ++i) drops += lc.drops[i];
      std::fprintf(
          stderr,
          "[run %6.1f s] %-9s scans %llu  packets %llu (dropped %llu)  pose %.2f,%.2f,%.2f "
          "yaw %.0f  nodes %u  frontiers %u  stops %llu [%s]%s\n",
          t, to_string(st.state), (unsigned long long)pc.scans, (unsigned long long)lc.datagrams,
          (unsigned long long)drops, p.x_m, p.y_m, p.z_m, p.yaw_rad * 180 / M_PI, st.nodes,
          st.frontier_nodes, (unsigned long long)autonomy.safety_stops(),
          mask_names(autonomy.active_stop_mask()).c_str(), describe_target(st).c_str());
    }
    if (const int sig = g_signal.load()) {
      summary.end_reason = std::string("stopped by ") + (sig == SIGINT ? "SIGINT" : "SIGTERM");
      break;
    }
    if (st.state == ExplorationState::kComplete) {
      summary.completed = true;
      summary.end_reason = "exploration complete";
      break;
    }
    if (st.state == ExplorationState::kStranded) {
      char why[160];
      std::snprintf(why, sizeof why,
                    "stranded: %u frontier clusters unreachable from the robot, cut off in %u of "
                    "%u graph nodes",
                    st.clusters_unreachable, st.robot_component_nodes, st.nodes);
      summary.end_reason = why;
      break;
    }
    if (duration_s > 0 && t >= duration_s) {
      char why[64];
      std::snprintf(why, sizeof why, "duration reached (%.0f s)", duration_s);
      summary.end_reason = why;
      break;
    }
  }
  // Commanded stop first: the control task sends zero velocity from its next period on.
  const uint64_t stops_before = autonomy.safety_stops();
  autonomy.set_operator_stop(true);
  const double period = 1.0 / std::max(1.0, params.rates.control.rate_hz);
  std::this_thread::sleep_for(std::chrono::duration<double>(3 * period));
  summary.run_time_s = double(clock.now_ns() - t0) * 1e-9;
  autonomy.scheduler().stop();
  if (!platform.command_stop())
    warn(
        "the link refused the final stop (zero velocity / StopMove): the robot's own command "
        "timeout stops it");
  if (recorder) {
    recorder->stop();
    summary.record_written = recorder->written();
    writer.close();
  }
  for (int f : floors) summary.floors_visited.push_back(f);
  summary.safety_stops = stops_before;

  std::printf("storey run: %s after %.1f s\n%s", summary.end_reason.c_str(), summary.run_time_s,
              autonomy.scheduler().report().c_str());
  const auto files = write_live_record(out_dir, autonomy, platform, summary, &err);
  if (!err.empty()) {
    std::fprintf(stderr, "storey run: %s\n", err.c_str());
    return 1;
  }
  std::printf("run record: %s/report.md (%zu files)\n", out_dir.c_str(), files.size());
  return 0;
}

}  // namespace storey::firmware
