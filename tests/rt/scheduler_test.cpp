#include "rt/scheduler.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace storey::rt {
namespace {

constexpr std::int64_t kSec = 1'000'000'000;

using Log = std::vector<std::pair<std::string, std::int64_t>>;  // (task, virtual time)

// 50/10/2 Hz over 10 s of virtual time, recording who ran when.
Log run_lockstep(std::int64_t t_end, int steps) {
  VirtualClock clock(5 * kSec);  // any start: the phase is fixed by the first run_until
  Log log;
  auto rec = [&](const char* n) {
    return [&log, &clock, n] { log.emplace_back(n, clock.now_ns()); };
  };
  const TaskSpec tasks[] = {
      {"control", 50, 2000, 0, -1, rec("control")},
      {"map", 10, 50000, 0, -1, rec("map")},
      {"plan", 2, 200000, 0, -1, rec("plan")},
  };
  Scheduler s(tasks);
  for (int k = 1; k <= steps; ++k) s.run_until(clock, 5 * kSec + t_end * k / steps);
  EXPECT_EQ(clock.now_ns(), 5 * kSec + t_end);
  return log;
}

TEST(SchedulerLockstep, ExactCountsAndOrder) {
  const Log log = run_lockstep(10 * kSec, 1);
  int control = 0, map = 0, plan = 0;
  for (const auto& [n, t] : log) {
    control += n == "control";
    map += n == "map";
    plan += n == "plan";
    EXPECT_LT(t, 15 * kSec);  // half-open: releases at exactly t_end belong to the next call
  }
  EXPECT_EQ(control, 500);
  EXPECT_EQ(map, 100);
  EXPECT_EQ(plan, 20);
  // At t=0 all three are due: table order. Then control alone at 20 ms.
  ASSERT_GE(log.size(), 4u);
  EXPECT_EQ(log[0], (std::pair<std::string, std::int64_t>{"control", 5 * kSec}));
  EXPECT_EQ(log[1], (std::pair<std::string, std::int64_t>{"map", 5 * kSec}));
  EXPECT_EQ(log[2], (std::pair<std::string, std::int64_t>{"plan", 5 * kSec}));
  EXPECT_EQ(log[3], (std::pair<std::string, std::int64_t>{"control", 5 * kSec + 20'000'000}));
  // Virtual time never goes backwards.
  for (std::size_t i = 1; i < log.size(); ++i) ASSERT_LE(log[i - 1].second, log[i].second);
}

TEST(SchedulerLockstep, DeterministicAcrossRunsAndStepSizes) {
  const Log a = run_lockstep(10 * kSec, 1);
  const Log b = run_lockstep(10 * kSec, 1);
  const Log c = run_lockstep(10 * kSec, 37);  // many small run_until calls: same schedule
  EXPECT_EQ(a, b);
  EXPECT_EQ(a, c);
}

TEST(SchedulerLockstep, EventTasksPolledAtBaseRateAndStats) {
  VirtualClock clock;
  int polls = 0, ticks = 0;
  TraceRing trace(64);
  const TaskSpec tasks[] = {
      {"ingest", 0, 100, 0, -1, [&] { ++polls; }},
      {"tick", 100, 100, 0, -1, [&] { ++ticks; }},
  };
  SchedulerOptions opt;
  opt.lockstep_event_hz = 200;
  opt.trace = &trace;
  Scheduler s(tasks, opt);
  s.run_until(clock, 1 * kSec);
  EXPECT_EQ(polls, 200);
  EXPECT_EQ(ticks, 100);
  const auto r = s.reports();
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].runs, 200u);
  EXPECT_EQ(r[1].runs, 100u);
  EXPECT_EQ(r[1].jitter.count, 100u);
  EXPECT_EQ(r[1].jitter.max_ns, 0);  // lockstep releases are exact
  EXPECT_EQ(r[0].missed, 0u);
  EXPECT_EQ(trace.recorded(), 300u);
  const std::string table = s.report();
  EXPECT_NE(table.find("ingest"), std::string::npos);
  EXPECT_NE(table.find("event"), std::string::npos);
  EXPECT_NE(table.find("jitter p99"), std::string::npos);
}

TEST(Scheduler, TableErrorsNameTaskAndField) {
  auto fn = [] {};
  auto expect_error = [](std::vector<TaskSpec> t, const std::string& what) {
    try {
      Scheduler s(t);
      ADD_FAILURE() << "no error for " << what;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  expect_error({{"map", -1, 0, 0, -1, fn}}, "'map': rate_hz");
  expect_error({{"map", 10, 0, 120, -1, fn}}, "'map': priority");
  expect_error({{"map", 10, 0, 0, -1, nullptr}}, "'map': fn is empty");
  expect_error({{"map", 10, 0, 0, -1, fn}, {"map", 5, 0, 0, -1, fn}}, "#1 'map': duplicate");
  expect_error({{"", 10, 0, 0, -1, fn}}, "name is empty");
  expect_error({}, "empty task table");
}

TEST(SchedulerRealtime, EventTaskWithoutFdFailsToStart) {
  const TaskSpec tasks[] = {{"ingest", 0, 100, 0, -1, [] {}}};
  Scheduler s(tasks);
  const StartResult r = s.start();
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("'ingest'"), std::string::npos) << r.error;
  EXPECT_FALSE(s.running());
}

// Real threads, real clock: only generous bounds (the machine is shared and may be loaded).
TEST(SchedulerRealtime, HundredHertzForHalfASecondAndEventTask) {
  int pipe_fd[2];
  ASSERT_EQ(pipe(pipe_fd), 0);
  std::atomic<int> bytes{0};
  const TaskSpec tasks[] = {
      {"tick", 100, 5000, 0, -1, [] {}},
      {"reader", 0, 5000, 0, -1,
       [&] {
         char buf[16];
         const ssize_t n = read(pipe_fd[0], buf, sizeof buf);
         if (n > 0) bytes += static_cast<int>(n);
       },
       pipe_fd[0]},
  };
  std::vector<std::string> warnings;
  SchedulerOptions opt;
  opt.warn = [&](const std::string& w) { warnings.push_back(w); };
  Scheduler s(tasks, opt);
  const StartResult r = s.start();
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_TRUE(s.running());
  std::this_thread::sleep_for(std::chrono::milliseconds(250));
  ASSERT_EQ(write(pipe_fd[1], "abc", 3), 3);
  std::this_thread::sleep_for(std::chrono::milliseconds(250));
  s.stop();
  EXPECT_FALSE(s.running());
  const auto rep = s.reports();
  // ~50 expected; anything from 10 to 60 means the loop works on a busy machine.
  EXPECT_GE(rep[0].runs, 10u);
  EXPECT_LE(rep[0].runs, 60u);
  EXPECT_EQ(rep[0].jitter.count, rep[0].runs);
  EXPECT_EQ(bytes.load(), 3);
  EXPECT_GE(rep[1].runs, 1u);
  EXPECT_TRUE(warnings.empty());  // nothing requested that could be unavailable
  close(pipe_fd[0]);
  close(pipe_fd[1]);
}

// Asking for SCHED_FIFO, a CPU and mlockall either works or yields exactly one warning per
// unavailable feature; the task runs either way.
TEST(SchedulerRealtime, UnavailableFeaturesWarnOnceAndContinue) {
  std::atomic<int> runs{0};
  const TaskSpec tasks[] = {
      {"a", 200, 0, 10, 9999, [&] { ++runs; }},  // CPU 9999 cannot exist
      {"b", 200, 0, 10, 9998, [&] { ++runs; }},
  };
  std::vector<std::string> warnings;
  SchedulerOptions opt;
  opt.warn = [&](const std::string& w) { warnings.push_back(w); };
  Scheduler s(tasks, opt);
  const StartResult r = s.start();
  ASSERT_TRUE(r.ok) << r.error;
  while (runs.load() < 4) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  s.stop();
  EXPECT_EQ(r.pinned_tasks, 0);
  int affinity = 0, fifo = 0;
  for (const auto& w : warnings) {
    affinity += w.find("CPU affinity") != std::string::npos;
    fifo += w.find("SCHED_FIFO") != std::string::npos;
  }
  EXPECT_EQ(affinity, 1);
  EXPECT_EQ(fifo, r.fifo_tasks == 2 ? 0 : 1);
}

TEST(SchedulerRealtime, LockstepWhileRunningIsRefused) {
  const TaskSpec tasks[] = {{"t", 100, 0, 0, -1, [] {}}};
  Scheduler s(tasks);
  ASSERT_TRUE(s.start().ok);
  VirtualClock c;
  EXPECT_THROW(s.run_until(c, kSec), std::logic_error);
  s.stop();
}

}  // namespace
}  // namespace storey::rt
