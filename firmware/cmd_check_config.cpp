// storey check-config FILE: validate a configuration (and its includes) without running.
// Prints "FILE: ok" and a summary, or every error as `file:line: key: reason` and exits 2.
#include <cstdio>
#include <string>
#include <string_view>

#include "config/parameters.hpp"
#include "firmware/commands.hpp"

namespace storey::firmware {

namespace {

void print_help(FILE* out) {
  std::fprintf(out,
               "usage: storey check-config FILE\n\n"
               "Loads FILE and every file it includes, checks every key (unknown keys, types,\n"
               "ranges, required values, cross-field rules) and prints either 'FILE: ok' with a\n"
               "summary, or each error as 'file:line: key: reason'.\n\n"
               "exit status: 0 valid, 2 invalid or bad usage\n");
}

const char* on_off(bool b) {
  return b ? "on" : "off";
}

void print_summary(const std::string& path, const config::Result& r) {
  const config::Parameters& p = r.params;
  std::printf("%s: ok\n", path.c_str());
  std::string files;
  for (const std::string& f : r.files) files += (files.empty() ? "" : ", ") + f;
  std::printf("  files:    %s\n", files.c_str());
  const config::SensorConfig& s = p.sensor;
  std::printf("  sensor:   %s from %s to %s:%d, range %g-%g m, %g Hz\n",
              std::string(config::to_string(s.type)).c_str(),
              s.sensor_address.empty() ? "any" : s.sensor_address.c_str(), s.host_address.c_str(),
              s.data_port, s.min_range_m, s.max_range_m, s.scan_rate_hz);
  const config::LinkConfig& l = p.link;
  switch (l.transport) {
    case config::LinkTransport::kDds:
      std::printf("  link:     dds domain %d, interface %s\n", l.dds.domain_id,
                  l.dds.interface.empty() ? "(auto)" : l.dds.interface.c_str());
      break;
    case config::LinkTransport::kUdp:
      std::printf("  link:     udp commands to %s:%d, state on %s:%d\n",
                  l.udp.robot_address.c_str(), l.udp.robot_port, l.udp.local_address.c_str(),
                  l.udp.local_port);
      break;
    case config::LinkTransport::kCan:
      std::printf("  link:     can on %s\n", l.can.interface.c_str());
      break;
    case config::LinkTransport::kSim:
      std::printf("  link:     sim (in-process)\n");
      break;
  }
  std::printf("  realtime: sched_fifo %s, mlockall %s, cpu_pinning %s\n",
              on_off(p.realtime.sched_fifo), on_off(p.realtime.mlockall),
              on_off(p.realtime.cpu_pinning));
  std::printf("  method:   voxel %g m, N_min %d, r_e %g m, k_max %d, r_z %g m, W %d, K %d\n",
              p.map.voxel_size_m, p.map.n_min, p.graph.r_e_m, p.graph.k_max, p.plan.r_z_m,
              p.plan.window_w, p.plan.max_candidates_k);
  std::printf("  tasks:    %-10s %8s %10s %5s %4s\n", "name", "rate", "budget", "prio", "cpu");
  for (const config::RateTable::Row& row : p.rates.rows()) {
    char rate[16];
    if (row.rate->rate_hz > 0) {
      std::snprintf(rate, sizeof rate, "%g Hz", row.rate->rate_hz);
    } else {
      std::snprintf(rate, sizeof rate, "event");
    }
    char cpu[8];
    std::snprintf(cpu, sizeof cpu, "%d", row.rate->cpu);
    std::printf("            %-10s %8s %7d us %5d %4s\n", std::string(row.name).c_str(), rate,
                row.rate->budget_us, row.rate->priority, row.rate->cpu < 0 ? "any" : cpu);
  }
}

}  // namespace

int cmd_check_config(int argc, char** argv) {
  std::string path;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      print_help(stdout);
      return 0;
    }
    if (arg.size() > 1 && arg[0] == '-') {
      std::fprintf(stderr, "storey check-config: unknown option '%s' (see --help)\n", argv[i]);
      return 2;
    }
    if (!path.empty()) {
      std::fprintf(stderr, "storey check-config: one FILE only (got '%s' and '%s')\n", path.c_str(),
                   argv[i]);
      return 2;
    }
    path = arg;
  }
  if (path.empty()) {
    std::fprintf(stderr, "storey check-config: missing FILE (usage: storey check-config FILE)\n");
    return 2;
  }
  const config::Result r = config::load(path);
  if (!r.ok()) {
    for (const config::ConfigError& e : r.errors) {
      std::fprintf(stderr, "%s\n", e.to_string().c_str());
    }
    std::fprintf(stderr, "%s: %zu error%s\n", path.c_str(), r.errors.size(),
                 r.errors.size() == 1 ? "" : "s");
    return 2;
  }
  print_summary(path, r);
  return 0;
}

}  // namespace storey::firmware
