// Scheduler period jitter (actual start - ideal start) at 50, 100 and 1000 Hz, with and without
// SCHED_FIFO, while a busy-loop thread keeps the other core at 100 % (cyclictest-style).
// Reports jitter p50/p99/max in microseconds as counters; `fifo` says whether SCHED_FIFO was
// actually granted (it may not be, e.g. in an unprivileged container).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>

#include "rt/rt_setup.hpp"
#include "rt/scheduler.hpp"

namespace {

using namespace storey;

void sched_jitter(benchmark::State& state, int rate_hz, bool fifo, double seconds) {
  const int ncpu = static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN));
  const int task_cpu = ncpu >= 2 ? 1 : -1;
  std::atomic<bool> stop{false};
  std::thread busy([&] {
    if (ncpu >= 2) rt::pin_cpu(0);  // the other core
    volatile std::uint64_t x = 0;
    while (!stop.load(std::memory_order_relaxed)) x = x + 1;
  });
  rt::TaskReport rep;
  rt::StartResult started;
  std::string warnings;
  for (auto _ : state) {
    const rt::TaskSpec tasks[] = {
        {"jitter", static_cast<double>(rate_hz), 100, fifo ? 80 : 0, task_cpu, [] {}}};
    rt::SchedulerOptions opt;
    opt.warn = [&](const std::string& w) { warnings += w + "; "; };
    rt::Scheduler s(tasks, opt);
    started = s.start();
    if (!started.ok) {
      state.SkipWithError(started.error.c_str());
      break;
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
    s.stop();
    rep = s.reports()[0];
  }
  stop = true;
  busy.join();
  auto us = [](std::int64_t ns) { return static_cast<double>(ns) / 1000.0; };
  state.counters["jitter_p50_us"] = us(rep.jitter.p50_ns);
  state.counters["jitter_p99_us"] = us(rep.jitter.p99_ns);
  state.counters["jitter_max_us"] = us(rep.jitter.max_ns);
  state.counters["runs"] = static_cast<double>(rep.runs);
  state.counters["missed"] = static_cast<double>(rep.missed);
  state.counters["fifo"] = started.fifo_tasks;
  if (!warnings.empty()) state.SetLabel(warnings);
}

const bool registered = [] {
  struct Case {
    int hz;
    double seconds;  // enough periods for a meaningful p99 (>= 300 samples)
  };
  for (Case c : {Case{50, 8.0}, Case{100, 10.0}, Case{1000, 5.0}}) {
    for (bool fifo : {true, false}) {
      const std::string name =
          "sched_jitter/" + std::to_string(c.hz) + "hz/" + (fifo ? "fifo" : "other");
      benchmark::RegisterBenchmark(name.c_str(), sched_jitter, c.hz, fifo, c.seconds)
          ->Iterations(1)
          ->UseRealTime()
          ->Unit(benchmark::kMillisecond);
    }
  }
  return true;
}();

}  // namespace
