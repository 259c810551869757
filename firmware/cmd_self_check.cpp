// storey self-check: a quick end-to-end check of this build on this machine, without any
// sensor or robot: default configuration, lockstep scheduler determinism, the SPSC queue across
// two threads, the real-time scheduler (with its warnings where SCHED_FIFO etc. are refused),
// and the trace export. Exit 0 when every check passes, 1 otherwise.
#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "config/parameters.hpp"
#include "firmware/commands.hpp"
#include "rt/clock.hpp"
#include "rt/scheduler.hpp"
#include "rt/spsc_queue.hpp"
#include "rt/trace.hpp"

namespace storey::firmware {

namespace {

int failures = 0;

void check(bool ok, const char* what, const std::string& detail) {
  std::printf("  [%s] %-36s %s\n", ok ? " ok " : "FAIL", what, detail.c_str());
  if (!ok) ++failures;
}

// Runs the configured task table in lockstep for `seconds` of virtual time and returns the
// execution order (task indices); counts per task go to `counts`.
std::vector<std::uint8_t> lockstep_order(const config::RateTable& rates, double seconds,
                                         std::vector<std::uint64_t>& counts) {
  std::vector<std::uint8_t> order;
  std::vector<rt::TaskSpec> table;
  const auto rows = rates.rows();
  counts.assign(rows.size(), 0);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    table.push_back({rows[i].name.data(), rows[i].rate->rate_hz, rows[i].rate->budget_us, 0, -1,
                     [&order, &counts, i] {
                       order.push_back(static_cast<std::uint8_t>(i));
                       ++counts[i];
                     }});
  }
  rt::Scheduler sched(table);
  rt::VirtualClock clock;
  sched.run_until(clock, static_cast<std::int64_t>(seconds * 1e9));
  return order;
}

}  // namespace

int cmd_self_check(int argc, char** argv) {
  if (argc > 1) {
    const std::string a = argv[1];
    if (a == "--help" || a == "-h") {
      std::printf(
          "usage: storey self-check\n\nChecks this build without sensor or robot: default\n"
          "configuration, lockstep determinism, SPSC queue, real-time scheduler, trace export.\n");
      return 0;
    }
    std::fprintf(stderr, "storey self-check: unexpected argument '%s'\n", argv[1]);
    return 2;
  }
  std::printf("storey %s self-check\n", kVersion);

  // 1. The default configuration loads and validates.
  const std::string path = default_config_path();
  const config::Result cfg = config::load(path);
  std::string cfg_detail = path;
  if (!cfg.ok()) cfg_detail += ": " + cfg.errors.front().to_string();
  check(cfg.ok(), "default configuration", cfg_detail);
  const config::RateTable rates = cfg.params.rates;

  // 2. Lockstep: 10 virtual seconds give exactly rate x 10 runs of every periodic task, and
  // two runs give the same order (determinism).
  std::vector<std::uint64_t> counts_a, counts_b;
  const auto order_a = lockstep_order(rates, 10.0, counts_a);
  const auto order_b = lockstep_order(rates, 10.0, counts_b);
  bool counts_ok = true;
  std::string counts_detail;
  const auto rows = rates.rows();
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].rate->rate_hz <= 0) continue;
    const auto expected = static_cast<std::uint64_t>(rows[i].rate->rate_hz * 10.0 + 0.5);
    counts_ok = counts_ok && counts_a[i] == expected;
    counts_detail += std::string(rows[i].name) + "=" + std::to_string(counts_a[i]) + " ";
  }
  check(counts_ok, "lockstep run counts (10 s virtual)", counts_detail);
  check(order_a == order_b, "lockstep determinism",
        std::to_string(order_a.size()) + " runs, identical order twice");

  // 3. SPSC queue: 1,000,000 items across two threads, nothing lost, order kept.
  {
    constexpr std::uint64_t kItems = 1'000'000;
    rt::SpscQueue<std::uint64_t> q(1024);
    std::thread producer([&q] {
      for (std::uint64_t i = 0; i < kItems; ++i) {
        while (!q.try_push(i)) std::this_thread::yield();
      }
    });
    std::uint64_t expected = 0;
    bool in_order = true;
    while (expected < kItems) {
      std::uint64_t v;
      if (q.try_pop(v)) {
        in_order = in_order && v == expected;
        ++expected;
      } else {
        std::this_thread::yield();
      }
    }
    producer.join();
    check(in_order, "SPSC queue across two threads", "1000000 items, in order, none lost");
  }

  // 4. Real-time scheduler: a 100 Hz task for 0.3 s with the configured priority; features
  // this machine refuses are reported as warnings, not failures.
  {
    rt::TraceRing trace(4096);
    std::atomic<int> runs{0};
    const rt::TaskSpec table[] = {
        {"control", 100.0, 2000, rates.control.priority, -1, [&runs] { ++runs; }},
    };
    rt::SchedulerOptions opts;
    opts.trace = &trace;
    opts.warn = [](const std::string& w) { std::printf("  [warn] %s\n", w.c_str()); };
    rt::Scheduler sched(table, opts);
    const rt::StartResult started = sched.start();
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    sched.stop();
    const int n = runs.load();
    check(started.ok && n >= 15 && n <= 45, "real-time scheduler (100 Hz, 0.3 s)",
          std::to_string(n) + " runs, SCHED_FIFO " + (started.fifo_tasks ? "on" : "off"));
    std::printf("%s", sched.report().c_str());
    std::ostringstream json;
    trace.write_chrome_json(json);
    check(json.str().find("\"traceEvents\"") != std::string::npos && trace.recorded() > 0,
          "trace export (Chrome JSON)", std::to_string(trace.recorded()) + " events");
  }

  std::printf("self-check: %s (%d failure%s)\n", failures ? "FAILED" : "passed", failures,
              failures == 1 ? "" : "s");
  return failures ? 1 : 0;
}

}  // namespace storey::firmware
