// storey replay FILE: recorded packets (pcap, pcapng, Livox .lvx2) through the very same
// ingestion path as live (UdpReceiver::process_datagram -> rt queue -> ScanAssembler), at the
// recorded timing, scaled, or as fast as possible. Deterministic: everything runs in capture
// order on one thread, so timing changes nothing but wall time.
// Writes DIR/replay.json (packets, points, scans, drops by reason) and, with --profile, a latency
// table per stage and DIR/trace.json (Chrome trace events, opens in Perfetto).
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Geometry>

#include "config/parameters.hpp"
#include "drivers/lidar/mid360.hpp"
#include "drivers/lidar/scan_assembler.hpp"
#include "drivers/lidar/scan_csv.hpp"
#include "drivers/lidar/udp_receiver.hpp"
#include "drivers/lidar/vlp16.hpp"
#include "drivers/pcap/lvx2_reader.hpp"
#include "drivers/pcap/pcap_reader.hpp"
#include "firmware/autonomy.hpp"
#include "firmware/commands.hpp"
#include "firmware/replay_platform.hpp"
#include "rt/clock.hpp"
#include "rt/latency_stats.hpp"
#include "rt/spsc_queue.hpp"
#include "rt/trace.hpp"

namespace storey::firmware {

namespace lidar = drivers::lidar;
namespace pcap = drivers::pcap;

namespace {

void print_help(FILE* out) {
  std::fprintf(
      out,
      "usage: storey replay FILE [--sensor vlp16|mid360] [--rate X | --fast] [--profile]\n"
      "                    [--out DIR] [--export-scans DIR] [--config FILE] [--no-map]\n\n"
      "Drives LiDAR ingestion, scan assembly, and the firmware's map and graph tasks from\n"
      "recorded packets: pcap or pcapng (tcpdump, Wireshark; Ethernet, VLAN, Linux cooked\n"
      "SLL/SLL2, raw IP) or a Livox Viewer 2 .lvx2. A LiDAR capture holds no odometry: the\n"
      "robot is taken to stand still at the origin, the sensor at the configured mounting.\n\n"
      "  --sensor S         vlp16 (default; .lvx2 files default to mid360)\n"
      "  --rate X           replay at X times the recorded timing (default 1)\n"
      "  --fast             as fast as possible\n"
      "  --profile          print per-stage and per-task latency; write DIR/trace.json (tasks)\n"
      "                     and DIR/trace_ingest.json (per-packet decode and assembly)\n"
      "  --config FILE      parameters (default config/default.yaml)\n"
      "  --no-map           ingestion and scan assembly only\n"
      "  --out DIR          output folder (default out/replay)\n"
      "  --export-scans D   each assembled scan as D/scan_NNNNNN.csv (sensor frame: x,y,z,\n"
      "                     intensity,ring,time_offset_ns; packet order; no-return points left "
      "out)\n\n"
      "writes DIR/replay.json: packets, points, scans, drops by reason, and the map and graph\n"
      "they built (volumes, nodes, frontiers).\n");
}

std::string json_escape(const std::string& s) {
  std::string o;
  for (char ch : s) {
    if (ch == '"' || ch == '\\') o += '\\';
    if (static_cast<unsigned char>(ch) < 0x20) continue;
    o += ch;
  }
  return o;
}

bool ends_with(const std::string& s, const char* suffix) {
  const std::size_t n = std::strlen(suffix);
  return s.size() >= n && s.compare(s.size() - n, n, suffix) == 0;
}

// Counts scans and writes them out when asked (file I/O: this is a non-RT command).
class ReplaySink final : public lidar::ScanSink {
 public:
  ReplaySink(std::string export_dir, lidar::ScanSink* next)
      : dir_(std::move(export_dir)), next_(next) {}
  void on_scan(const lidar::Scan& scan) override {
    if (next_ != nullptr) next_->on_scan(scan);
    ++scans_;
    points_ += scan.points.size();
    if (!dir_.empty() && error_.empty()) {
      std::string err;
      if (!lidar::write_scan_csv(lidar::scan_csv_path(dir_, scan.index), scan, &err)) error_ = err;
    }
  }
  std::uint64_t scans() const { return scans_; }
  std::uint64_t points() const { return points_; }
  const std::string& error() const { return error_; }

 private:
  std::string dir_, error_;
  lidar::ScanSink* next_;
  std::uint64_t scans_ = 0, points_ = 0;
};

struct Stage {
  const char* name;
  rt::LatencyHistogram hist;
};

}  // namespace

int cmd_replay(int argc, char** argv) {
  std::string file, out_dir = "out/replay", export_dir;
  std::string sensor_name, config_path;
  double rate = 1.0;
  bool fast = false, profile = false, with_map = true;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](const char* flag) -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "storey replay: %s needs a value\n", flag);
        return nullptr;
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      print_help(stdout);
      return 0;
    } else if (a == "--sensor") {
      const char* v = value("--sensor");
      if (!v) return 2;
      sensor_name = v;
    } else if (a == "--rate") {
      const char* v = value("--rate");
      if (!v) return 2;
      char* end = nullptr;
      rate = std::strtod(v, &end);
      if (end == v || *end != '\0' || !(rate > 0.0) || rate > 1e6) {
        std::fprintf(stderr, "storey replay: --rate '%s' must be a number > 0\n", v);
        return 2;
      }
    } else if (a == "--fast") {
      fast = true;
    } else if (a == "--profile") {
      profile = true;
    } else if (a == "--no-map") {
      with_map = false;
    } else if (a == "--config") {
      const char* v = value("--config");
      if (!v) return 2;
      config_path = v;
    } else if (a == "--out") {
      const char* v = value("--out");
      if (!v) return 2;
      out_dir = v;
    } else if (a == "--export-scans") {
      const char* v = value("--export-scans");
      if (!v) return 2;
      export_dir = v;
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "storey replay: unknown option '%s' (see --help)\n", a.c_str());
      return 2;
    } else if (file.empty()) {
      file = a;
    } else {
      std::fprintf(stderr, "storey replay: more than one input file ('%s')\n", a.c_str());
      return 2;
    }
  }
  if (file.empty()) {
    std::fprintf(stderr, "storey replay: no input file (see --help)\n");
    return 2;
  }
  const bool is_lvx2 = ends_with(file, ".lvx2");
  if (sensor_name.empty()) sensor_name = is_lvx2 ? "mid360" : "vlp16";
  if (sensor_name != "vlp16" && sensor_name != "mid360") {
    std::fprintf(stderr, "storey replay: --sensor '%s' must be vlp16 or mid360\n",
                 sensor_name.c_str());
    return 2;
  }
  const bool mid360 = sensor_name == "mid360";
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) {
    std::fprintf(stderr, "storey replay: cannot create %s: %s\n", out_dir.c_str(),
                 ec.message().c_str());
    return 2;
  }
  if (!export_dir.empty()) {
    std::filesystem::create_directories(export_dir, ec);
    if (ec) {
      std::fprintf(stderr, "storey replay: cannot create %s: %s\n", export_dir.c_str(),
                   ec.message().c_str());
      return 2;
    }
  }

  // The firmware's parameters: the mounting places the sensor, the task table runs map + graph.
  if (config_path.empty()) config_path = default_config_path();
  const config::Result cfg = config::load(config_path);
  if (!cfg.ok()) {
    for (const auto& e : cfg.errors) std::fprintf(stderr, "%s\n", e.to_string().c_str());
    std::fprintf(stderr, "storey replay: invalid configuration %s\n", config_path.c_str());
    return 2;
  }
  const config::SensorConfig& sc = cfg.params.sensor;
  const Eigen::Quaterniond q_mount =
      Eigen::AngleAxisd(sc.mounting_rpy_rad[2], Eigen::Vector3d::UnitZ()) *
      Eigen::AngleAxisd(sc.mounting_rpy_rad[1], Eigen::Vector3d::UnitY()) *
      Eigen::AngleAxisd(sc.mounting_rpy_rad[0], Eigen::Vector3d::UnitX());
  lidar::RigidTransform sensor_in_world;
  sensor_in_world.qw = float(q_mount.w()), sensor_in_world.qx = float(q_mount.x());
  sensor_in_world.qy = float(q_mount.y()), sensor_in_world.qz = float(q_mount.z());
  sensor_in_world.tx = float(sc.mounting_xyz_m[0]);
  sensor_in_world.ty = float(sc.mounting_xyz_m[1]);
  sensor_in_world.tz = float(sc.mounting_xyz_m[2] + kBodyCentreHeightM);
  ReplayPlatform platform(sensor_in_world, Eigen::Vector3d::Zero());
  rt::VirtualClock virtual_clock;
  std::unique_ptr<Autonomy> autonomy;
  std::uint64_t autonomy_log_lines = 0;
  if (with_map) {
    AutonomyOptions ao;
    ao.params = cfg.params;
    ao.fov = mid360 ? core::graph::SensorFov::mid360() : core::graph::SensorFov::vlp16();
    ao.stop_on_overruns = false;  // lockstep on the capture's timeline
    ao.log = [&autonomy_log_lines](const std::string&) { ++autonomy_log_lines; };
    autonomy = std::make_unique<Autonomy>(platform, virtual_clock, ao);
    autonomy->suspend_task("plan", true);  // nobody to command: map and graph only
  }
  std::int64_t first_sensor_ns = -1;
  auto advance_firmware = [&](std::uint64_t capture_ns) {
    if (!autonomy) return;
    if (first_sensor_ns < 0) first_sensor_ns = static_cast<std::int64_t>(capture_ns);
    const std::int64_t t = static_cast<std::int64_t>(capture_ns) - first_sensor_ns;
    if (t <= virtual_clock.now_ns()) return;
    platform.set_time(double(t) * 1e-9);
    autonomy->run_until(virtual_clock, t);
  };

  // The live path: receiver (not opened: no socket) -> SPSC queue -> assembler.
  rt::SpscQueue<lidar::PointChunk> queue(64);
  lidar::UdpReceiver::Options ropt;
  ropt.sensor = mid360 ? lidar::SensorModel::mid360 : lidar::SensorModel::vlp16;
  ropt.port = mid360 ? lidar::kMid360HostPointPort : lidar::kVlp16DataPort;
  ropt.verify_crc = !is_lvx2;  // .lvx2 keeps no CRC
  auto receiver = std::make_unique<lidar::UdpReceiver>(ropt, queue);
  ReplaySink sink(export_dir, with_map ? &platform : nullptr);
  lidar::ScanAssembler::Options aopt;
  aopt.mode =
      mid360 ? lidar::ScanAssembler::Mode::time_window : lidar::ScanAssembler::Mode::rotation;
  lidar::ScanAssembler assembler(aopt, &sink);

  rt::MonotonicClock clock;
  rt::TraceRing trace(1 << 16);
  Stage decode{"decode", {}}, assemble{"assemble", {}};
  std::uint64_t position_packets = 0, position_errors = 0, other_port = 0;
  std::int64_t first_capture_ns = -1, wall_start_ns = clock.now_ns();

  auto pace = [&](std::uint64_t capture_ns) {
    if (fast) return;
    if (first_capture_ns < 0) {
      first_capture_ns = static_cast<std::int64_t>(capture_ns);
      wall_start_ns = clock.now_ns();
      return;
    }
    const double dt =
        static_cast<double>(static_cast<std::int64_t>(capture_ns) - first_capture_ns) / rate;
    clock.sleep_until(wall_start_ns + static_cast<std::int64_t>(dt));
  };
  auto drain = [&] {
    lidar::PointChunk chunk;
    while (queue.try_pop(chunk)) {
      const std::int64_t t0 = clock.now_ns();
      assembler.add_packet({chunk.points.data(), chunk.count},
                           mid360 ? chunk.sensor_stamp_ns : chunk.receive_time_ns, chunk.frame_cnt);
      const std::int64_t t1 = clock.now_ns();
      assemble.hist.record(t1 - t0);
      if (profile) trace.record("assemble", 1, t0, t1 - t0);
    }
  };
  auto feed = [&](std::span<const std::uint8_t> payload, std::uint32_t src, std::uint16_t sport,
                  std::uint64_t t_ns) {
    pace(t_ns);
    const std::int64_t t0 = clock.now_ns();
    receiver->process_datagram(payload, src, sport, t_ns);
    const std::int64_t t1 = clock.now_ns();
    decode.hist.record(t1 - t0);
    if (profile) trace.record("decode", 1, t0, t1 - t0);
    drain();
    advance_firmware(t_ns);
  };

  std::string input_error;
  pcap::FrameStats frame_stats;
  if (is_lvx2) {
    std::vector<std::uint8_t> bytes;
    pcap::Lvx2Reader reader;
    if (!pcap::load_file(file, bytes, &input_error) || !reader.open(bytes, &input_error)) {
      std::fprintf(stderr, "storey replay: %s\n", input_error.c_str());
      return 2;
    }
    pcap::Lvx2Package pkg;
    std::vector<std::uint8_t> datagram(2048);
    while (reader.next(pkg)) {
      const std::size_t n = pcap::lvx2_to_sdk_packet(pkg, 4800, datagram);
      if (n == 0) continue;  // counted by the decoder as malformed on the next valid call
      feed({datagram.data(), n}, 0, lidar::kMid360PointPort, pkg.header.timestamp);
    }
    if (!reader.error().empty()) input_error = reader.error();
  } else {
    pcap::PcapReader reader;
    if (!reader.open(file, &input_error)) {
      std::fprintf(stderr, "storey replay: %s\n", input_error.c_str());
      return 2;
    }
    if (mid360) {
      reader.add_port(lidar::kMid360PointPort);
      reader.add_port(lidar::kMid360HostPointPort);
    } else {
      reader.add_port(lidar::kVlp16DataPort);
      reader.add_port(lidar::kVlp16PositionPort);
    }
    pcap::UdpDatagram d;
    while (reader.next(d)) {
      if (!mid360 &&
          (d.dst_port == lidar::kVlp16PositionPort || d.src_port == lidar::kVlp16PositionPort)) {
        lidar::Vlp16Position pos;
        if (lidar::vlp16_decode_position(d.payload, pos) == lidar::DropReason::none) {
          ++position_packets;
        } else {
          ++position_errors;
        }
        continue;
      }
      if (mid360 && d.dst_port != lidar::kMid360HostPointPort &&
          d.src_port != lidar::kMid360PointPort) {
        ++other_port;
        continue;
      }
      feed(d.payload, d.src_addr, d.src_port, d.timestamp_ns);
    }
    frame_stats = reader.stats();
    input_error = reader.error();
  }
  assembler.flush();
  if (autonomy) {  // let the map task take the last sweeps (a few map periods)
    platform.set_time(double(virtual_clock.now_ns() + 500'000'000) * 1e-9);
    autonomy->run_until(virtual_clock, virtual_clock.now_ns() + 500'000'000);
  }
  if (!sink.error().empty()) {
    std::fprintf(stderr, "storey replay: %s\n", sink.error().c_str());
    return 1;
  }

  const lidar::UdpReceiver::Counters c = receiver->counters();
  std::uint64_t dropped = 0;
  for (std::size_t i = 1; i < lidar::kDropReasonCount; ++i) dropped += c.drops[i];
  const std::string json_path = out_dir + "/replay.json";
  std::ofstream js(json_path);
  js << "{\n  \"file\": \"" << file << "\",\n  \"sensor\": \"" << sensor_name << "\",\n"
     << "  \"packets\": " << c.datagrams << ",\n  \"accepted\": " << c.accepted << ",\n"
     << "  \"points\": " << c.points << ",\n  \"scans\": " << sink.scans() << ",\n"
     << "  \"scan_points\": " << sink.points() << ",\n"
     << "  \"position_packets\": " << position_packets << ",\n"
     << "  \"position_errors\": " << position_errors << ",\n"
     << "  \"lost_udp_cnt\": " << c.lost_udp_cnt << ",\n"
     << "  \"points_overflowed\": " << assembler.points_overflowed() << ",\n"
     << "  \"dropped\": " << dropped << ",\n  \"drops\": {";
  bool first = true;
  for (std::size_t i = 1; i < lidar::kDropReasonCount; ++i) {
    js << (first ? "" : ", ") << "\"" << lidar::to_string(static_cast<lidar::DropReason>(i))
       << "\": " << c.drops[i];
    first = false;
  }
  js << "},\n  \"capture\": {\"frames\": " << frame_stats.frames << ", \"udp\": " << frame_stats.udp
     << ", \"port_filtered\": " << frame_stats.port_filtered
     << ", \"not_ipv4\": " << frame_stats.not_ipv4
     << ", \"ip_fragments\": " << frame_stats.ip_fragments
     << ", \"truncated\": " << frame_stats.truncated << ", \"malformed\": " << frame_stats.malformed
     << ", \"ip_length_mismatch\": " << frame_stats.ip_length_mismatch
     << ", \"other_port\": " << other_port << "},\n"
     << "  \"input_error\": \"" << json_escape(input_error) << "\"";
  if (autonomy) {
    const auto w = autonomy->world();
    const core::map::TraversabilityMap& m = autonomy->map_for_record();
    js << ",\n  \"map\": {\"scans_inserted\": " << (w ? w->scans : 0)
       << ", \"occupied_volume_m3\": " << m.occupied_volume_m3()
       << ", \"traversable_volume_m3\": " << m.traversable_volume_m3()
       << ", \"graph_nodes\": " << (w ? w->graph.node_count() : 0)
       << ", \"graph_edges\": " << (w ? w->graph.edge_count() : 0)
       << ", \"frontier_nodes\": " << (w ? w->frontier_nodes : 0)
       << ", \"clusters\": " << (w ? w->clusters.size() : 0) << "}";
  }
  js << "\n}\n";
  js.close();
  if (!js) {
    std::fprintf(stderr, "storey replay: cannot write %s\n", json_path.c_str());
    return 1;
  }

  std::printf("replay %s (%s): %llu packets, %llu points, %llu scans, %llu dropped\n", file.c_str(),
              sensor_name.c_str(), static_cast<unsigned long long>(c.datagrams),
              static_cast<unsigned long long>(c.points),
              static_cast<unsigned long long>(sink.scans()),
              static_cast<unsigned long long>(dropped));
  if (!input_error.empty()) std::printf("  input stopped early: %s\n", input_error.c_str());
  if (profile) {
    std::printf("%-10s %10s %10s %10s %10s %10s\n", "stage", "count", "p50[us]", "p99[us]",
                "p99.9[us]", "max[us]");
    for (const Stage* s : {&decode, &assemble}) {
      const rt::LatencySummary q = s->hist.summary();
      std::printf("%-10s %10llu %10.1f %10.1f %10.1f %10.1f\n", s->name,
                  static_cast<unsigned long long>(q.count), q.p50_ns / 1e3, q.p99_ns / 1e3,
                  q.p999_ns / 1e3, q.max_ns / 1e3);
    }
    std::string err;
    if (!trace.write_chrome_json(out_dir + "/trace_ingest.json", &err) ||
        (autonomy && !autonomy->trace().write_chrome_json(out_dir + "/trace.json", &err))) {
      std::fprintf(stderr, "storey replay: %s\n", err.c_str());
      return 1;
    }
    if (autonomy) {
      std::printf("%s", autonomy->scheduler().report().c_str());
      std::printf("trace: %s/trace.json (tasks), %s/trace_ingest.json (packets)\n", out_dir.c_str(),
                  out_dir.c_str());
    } else {
      std::printf("trace: %s/trace_ingest.json\n", out_dir.c_str());
    }
  }
  std::printf("wrote %s\n", json_path.c_str());
  return input_error.empty() ? 0 : 1;
}

}  // namespace storey::firmware
