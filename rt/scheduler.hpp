// Fixed-rate task scheduler: real-time mode (a thread per task) and lockstep mode (one thread,
// virtual clock, deterministic). The whole task table is one plain array, written once by the
// firmware, e.g. (after ArduPilot's SCHED_TASK table):
//
//   const rt::TaskSpec kTasks[] = {
//   //  name       rate[Hz] budget[us] FIFO prio  cpu  body                      fd
//     {"ingest",       0,     500,       80,     1,  [&] { ingest.poll(); },  lidar_fd},
//     {"control",     50,    2000,       70,     1,  [&] { control.step(); }},
//     {"map",         10,   60000,       40,     0,  [&] { map.step(); }},
//     {"plan",         2,  200000,       30,     0,  [&] { plan.step(); }},
//     {"watchdog",    10,     200,       60,    -1,  [&] { watchdog.step(); }},
//   };
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "rt/clock.hpp"
#include "rt/latency_stats.hpp"
#include "rt/trace.hpp"

namespace storey::rt {

struct TaskSpec {
  const char* name;          // static string (also the trace event name)
  double rate_hz;            // > 0: periodic; 0: event-driven (see fd)
  std::int64_t budget_us;    // execution time above this counts as an overrun; 0 = none
  int priority;              // SCHED_FIFO priority 1..99; 0 = normal scheduling
  int cpu;                   // CPU to pin to; -1 = any
  std::function<void()> fn;  // the body; must not block (drain inputs, compute, publish)
  int fd = -1;               // event-driven, real-time mode: run fn when fd becomes readable
};

// Live statistics of one task, written only by the thread that runs it, readable anywhere.
struct TaskStats {
  LatencyHistogram jitter;  // actual start - ideal start [ns] (periodic tasks only)
  LatencyHistogram exec;    // execution time [ns]
  std::atomic<std::uint64_t> runs{0};
  std::atomic<std::uint64_t> overruns{0};  // exec > budget
  std::atomic<std::uint64_t> missed{0};    // periods skipped because the task ran late
};

// Copy of one task's statistics as plain data (for reports, JSON, tests).
struct TaskReport {
  std::string name;
  double rate_hz = 0;
  std::int64_t budget_us = 0;
  std::uint64_t runs = 0, overruns = 0, missed = 0;
  LatencySummary exec, jitter;
};

struct SchedulerOptions {
  bool lock_memory = false;         // mlockall at start() (real-time mode)
  bool use_priorities = true;       // apply TaskSpec::priority (SCHED_FIFO) in real-time mode
  bool pin_cpus = true;             // apply TaskSpec::cpu in real-time mode
  double lockstep_event_hz = 1000;  // lockstep: event-driven tasks are polled at this rate
  TraceRing* trace = nullptr;       // when set, every run is one trace event (tid = task + 1)
  // Receives one line per unavailable feature; default prints "storey: warning: ..." to stderr.
  std::function<void(const std::string&)> warn;
};

struct StartResult {
  bool ok = false;
  std::string error;  // why nothing was started
  bool memory_locked = false;
  int fifo_tasks = 0;    // tasks that got SCHED_FIFO
  int pinned_tasks = 0;  // tasks pinned to their CPU
};

class Scheduler {
 public:
  // Validates the table; throws std::invalid_argument naming the task and the field.
  explicit Scheduler(std::span<const TaskSpec> tasks, SchedulerOptions options = {});
  ~Scheduler();
  Scheduler(const Scheduler&) = delete;
  Scheduler& operator=(const Scheduler&) = delete;

  // ---- Real-time mode (called by the firmware's main thread) ----
  // Creates one thread per task; all periodic tasks are phase-aligned to one start time.
  // Unavailable features (mlockall, SCHED_FIFO, affinity) give one warning each and the
  // tasks run without them; a table unusable in this mode (event task without fd) fails.
  StartResult start();
  // Blocking: signals the threads and joins them (a periodic task finishes its current
  // sleep first, so this takes up to one period of the slowest task).
  void stop();
  bool running() const noexcept { return running_.load(std::memory_order_acquire); }

  // ---- Lockstep mode (single thread, no real-time threads running) ----
  // Runs every release with time in [clock.now_ns(), t_ns) in time order, ties in table
  // order, advancing `clock` to each release before the tasks run; ends with the clock at
  // t_ns. The first call fixes the phase: every task is first released at clock.now_ns().
  void run_until(VirtualClock& clock, std::int64_t t_ns);

  // ---- Statistics (any thread) ----
  std::size_t size() const noexcept { return tasks_.size(); }
  const TaskSpec& spec(std::size_t i) const { return tasks_[i].spec; }
  const TaskStats& stats(std::size_t i) const { return *tasks_[i].stats; }
  std::vector<TaskReport> reports() const;
  // Fixed-width text table: task, rate, budget, runs, exec p50/p99/max, jitter p99,
  // overruns, missed (times in us).
  std::string report() const;

 private:
  struct Task {
    TaskSpec spec;
    std::int64_t period_ns = 0;  // 0 = event-driven
    std::unique_ptr<TaskStats> stats;
    std::int64_t next_release_ns = 0;  // lockstep
    int epoll_fd = -1, stop_fd = -1;   // real-time event-driven tasks
  };
  void run_once(Task& t, std::uint32_t index, std::int64_t ideal_ns, std::int64_t start_ns,
                std::int64_t trace_start_ns);
  void periodic_loop(std::uint32_t index);
  void event_loop(std::uint32_t index);
  void close_fds();
  void warn(const std::string& msg) const;

  std::vector<Task> tasks_;
  SchedulerOptions options_;
  std::vector<std::thread> threads_;
  std::atomic<bool> running_{false};
  std::atomic<int> go_{0};  // 0 = wait, 1 = run, 2 = abort start
  std::int64_t start_ns_ = 0;
  bool lockstep_started_ = false;
  MonotonicClock clock_;
};

}  // namespace storey::rt
