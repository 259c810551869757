#include "rt/scheduler.hpp"

#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <cerrno>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "rt/rt_setup.hpp"

namespace storey::rt {

namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;
constexpr double kMaxRateHz = 100'000;  // 10 us period: beyond that a thread per task is wrong

std::string task_label(const TaskSpec& s, std::size_t i) {
  return "scheduler task #" + std::to_string(i) + " '" + (s.name ? s.name : "(null)") + "'";
}

}  // namespace

Scheduler::Scheduler(std::span<const TaskSpec> tasks, SchedulerOptions options)
    : options_(std::move(options)) {
  if (tasks.empty()) throw std::invalid_argument("scheduler: empty task table");
  if (!(options_.lockstep_event_hz > 0 && options_.lockstep_event_hz <= kMaxRateHz)) {
    throw std::invalid_argument("scheduler: lockstep_event_hz must be in (0, 100000]");
  }
  tasks_.reserve(tasks.size());
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    const TaskSpec& s = tasks[i];
    const std::string who = task_label(s, i);
    if (!s.name || !*s.name) throw std::invalid_argument(who + ": name is empty");
    if (!std::isfinite(s.rate_hz) || s.rate_hz < 0 || s.rate_hz > kMaxRateHz) {
      throw std::invalid_argument(who + ": rate_hz must be in [0, 100000] (0 = event-driven)");
    }
    if (s.budget_us < 0) throw std::invalid_argument(who + ": budget_us must be >= 0");
    if (s.priority < 0 || s.priority > 99) {
      throw std::invalid_argument(who + ": priority must be 0 (normal) or 1..99 (SCHED_FIFO)");
    }
    if (s.cpu < -1) throw std::invalid_argument(who + ": cpu must be -1 (any) or >= 0");
    if (!s.fn) throw std::invalid_argument(who + ": fn is empty");
    for (std::size_t j = 0; j < i; ++j) {
      if (std::strcmp(tasks_[j].spec.name, s.name) == 0) {
        throw std::invalid_argument(who + ": duplicate task name");
      }
    }
    Task t;
    t.spec = s;
    t.period_ns = s.rate_hz > 0 ? std::llround(kNsPerS / s.rate_hz) : 0;
    t.stats = std::make_unique<TaskStats>();
    tasks_.push_back(std::move(t));
    if (options_.trace) options_.trace->set_thread_name(static_cast<std::uint32_t>(i + 1), s.name);
  }
}

Scheduler::~Scheduler() {
  stop();
}

void Scheduler::warn(const std::string& msg) const {
  if (options_.warn) {
    options_.warn(msg);
  } else {
    std::fprintf(stderr, "storey: warning: %s\n", msg.c_str());
  }
}

// Shared by both modes. start_ns is on the mode's clock; exec time is always measured on the
// monotonic clock (in lockstep it is a profile of the real cost, not an input to any task).
void Scheduler::run_once(Task& t, std::uint32_t index, std::int64_t ideal_ns, std::int64_t start_ns,
                         std::int64_t trace_start_ns) {
  TaskStats& st = *t.stats;
  if (t.period_ns > 0) st.jitter.record(start_ns - ideal_ns);
  const std::int64_t t0 = monotonic_now_ns();
  t.spec.fn();
  const std::int64_t exec = monotonic_now_ns() - t0;
  st.exec.record(exec);
  st.runs.store(st.runs.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  if (t.spec.budget_us > 0 && exec > t.spec.budget_us * 1000) {
    st.overruns.store(st.overruns.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  }
  if (options_.trace) options_.trace->record(t.spec.name, index + 1, trace_start_ns, exec);
}

// ---------------------------------------------------------------- lockstep

void Scheduler::run_until(VirtualClock& clock, std::int64_t t_ns) {
  if (running()) throw std::logic_error("scheduler: run_until() while real-time threads run");
  const std::int64_t event_period = std::llround(kNsPerS / options_.lockstep_event_hz);
  if (!lockstep_started_) {
    for (Task& t : tasks_) t.next_release_ns = clock.now_ns();
    lockstep_started_ = true;
  }
  for (;;) {
    std::int64_t t_next = std::numeric_limits<std::int64_t>::max();
    for (const Task& t : tasks_) t_next = std::min(t_next, t.next_release_ns);
    if (t_next >= t_ns) break;
    clock.advance_to(t_next);
    for (std::uint32_t i = 0; i < tasks_.size(); ++i) {
      Task& t = tasks_[i];
      if (t.next_release_ns != t_next) continue;
      run_once(t, i, t_next, clock.now_ns(), t_next);
      t.next_release_ns += t.period_ns > 0 ? t.period_ns : event_period;
    }
  }
  clock.advance_to(t_ns);
}

// ---------------------------------------------------------------- real-time

StartResult Scheduler::start() {
  StartResult r;
  if (running()) {
    r.error = "scheduler: already started";
    return r;
  }
  // Event-driven tasks need their fd and a stop eventfd in one epoll set.
  for (std::size_t i = 0; i < tasks_.size(); ++i) {
    Task& t = tasks_[i];
    if (t.period_ns > 0) continue;
    const std::string who = task_label(t.spec, i);
    if (t.spec.fd < 0) {
      r.error = who + ": event-driven (rate_hz 0) needs a pollable fd in real-time mode";
    } else if ((t.epoll_fd = epoll_create1(EPOLL_CLOEXEC)) < 0 ||
               (t.stop_fd = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK)) < 0) {
      r.error = who + ": epoll/eventfd: " + std::strerror(errno);
    } else {
      epoll_event ev{};
      ev.events = EPOLLIN;
      ev.data.u32 = 0;
      if (epoll_ctl(t.epoll_fd, EPOLL_CTL_ADD, t.spec.fd, &ev) != 0) {
        r.error =
            who + ": cannot poll fd " + std::to_string(t.spec.fd) + ": " + std::strerror(errno);
      } else {
        ev.data.u32 = 1;
        if (epoll_ctl(t.epoll_fd, EPOLL_CTL_ADD, t.stop_fd, &ev) != 0) {
          r.error = who + ": epoll_ctl(eventfd): " + std::strerror(errno);
        }
      }
    }
    if (!r.error.empty()) {
      close_fds();
      return r;
    }
  }

  if (options_.lock_memory) {
    const SetupStatus s = lock_memory();
    r.memory_locked = s.ok();
    if (!s.ok()) warn("memory locking unavailable (" + s.message() + "); page faults possible");
  }

  go_.store(0);
  running_.store(true, std::memory_order_release);
  threads_.reserve(tasks_.size());
  for (std::uint32_t i = 0; i < tasks_.size(); ++i) {
    threads_.emplace_back([this, i] {
      go_.wait(0, std::memory_order_acquire);  // setup below happens before the loop
      if (go_.load(std::memory_order_acquire) != 1) return;
      if (tasks_[i].period_ns > 0) {
        periodic_loop(i);
      } else {
        event_loop(i);
      }
    });
  }

  // Priorities and affinity are applied from here, before the threads start their loops, so
  // that every failure is reported once, by one thread.
  std::string fifo_error, pin_error;
  for (std::uint32_t i = 0; i < tasks_.size(); ++i) {
    const TaskSpec& s = tasks_[i].spec;
    const pthread_t h = threads_[i].native_handle();
    if (options_.pin_cpus && s.cpu >= 0) {
      const SetupStatus st = pin_cpu(s.cpu, h);
      if (st.ok()) {
        ++r.pinned_tasks;
      } else if (pin_error.empty()) {
        pin_error = "CPU affinity unavailable (task '" + std::string(s.name) + "' cpu " +
                    std::to_string(s.cpu) + ": " + st.message() + "); tasks run on any CPU";
      }
    }
    if (options_.use_priorities && s.priority > 0) {
      const SetupStatus st = set_fifo(s.priority, h);
      if (st.ok()) {
        ++r.fifo_tasks;
      } else if (fifo_error.empty()) {
        fifo_error = "SCHED_FIFO unavailable (task '" + std::string(s.name) + "' priority " +
                     std::to_string(s.priority) + ": " + st.message() +
                     "); tasks run at normal priority (grant CAP_SYS_NICE or rtprio)";
      }
    }
  }
  if (!pin_error.empty()) warn(pin_error);
  if (!fifo_error.empty()) warn(fifo_error);

  // One common phase for all periodic tasks; 2 ms leaves time for the threads to park.
  start_ns_ = clock_.now_ns() + 2'000'000;
  go_.store(1, std::memory_order_release);
  go_.notify_all();
  r.ok = true;
  return r;
}

void Scheduler::periodic_loop(std::uint32_t index) {
  Task& t = tasks_[index];
  TaskStats& st = *t.stats;
  std::int64_t next = start_ns_;
  // Normal-priority threads get 50 us of timer slack by default (SCHED_FIFO gets none): ask
  // for 1 ns so a periodic task wakes at its deadline, not up to 50 us after it.
  prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
  // The cyclictest loop: absolute deadline, next += period, lateness measured every cycle.
  while (running_.load(std::memory_order_relaxed)) {
    clock_.sleep_until(next);
    if (!running_.load(std::memory_order_relaxed)) break;
    const std::int64_t start = clock_.now_ns();
    run_once(t, index, next, start, start);
    next += t.period_ns;
    const std::int64_t now = clock_.now_ns();
    if (now > next) {  // late: skip the releases already past instead of bursting to catch up
      const std::int64_t k = (now - next) / t.period_ns + 1;
      next += k * t.period_ns;
      st.missed.store(st.missed.load(std::memory_order_relaxed) + k, std::memory_order_relaxed);
    }
  }
}

void Scheduler::event_loop(std::uint32_t index) {
  Task& t = tasks_[index];
  epoll_event ev[2];
  while (running_.load(std::memory_order_relaxed)) {
    const int n = epoll_wait(t.epoll_fd, ev, 2, -1);
    if (n < 0) {
      if (errno == EINTR) continue;
      break;  // the fd set is broken; stop() still joins cleanly
    }
    bool readable = false;
    for (int k = 0; k < n; ++k) {
      if (ev[k].data.u32 == 1) return;  // stop requested
      readable = true;
    }
    if (readable) {
      const std::int64_t start = clock_.now_ns();
      run_once(t, index, start, start, start);
    }
  }
}

void Scheduler::stop() {
  if (threads_.empty()) {
    running_.store(false);
    close_fds();
    return;
  }
  running_.store(false, std::memory_order_release);
  if (go_.load() == 0) {  // start() never released the threads
    go_.store(2, std::memory_order_release);
    go_.notify_all();
  }
  for (Task& t : tasks_) {
    if (t.stop_fd >= 0) {
      const std::uint64_t one = 1;
      [[maybe_unused]] ssize_t n = write(t.stop_fd, &one, sizeof one);
    }
  }
  for (auto& th : threads_) th.join();
  threads_.clear();
  close_fds();
}

void Scheduler::close_fds() {
  for (Task& t : tasks_) {
    if (t.epoll_fd >= 0) close(t.epoll_fd);
    if (t.stop_fd >= 0) close(t.stop_fd);
    t.epoll_fd = t.stop_fd = -1;
  }
}

// ---------------------------------------------------------------- reports

std::vector<TaskReport> Scheduler::reports() const {
  std::vector<TaskReport> out;
  for (const Task& t : tasks_) {
    TaskReport r;
    r.name = t.spec.name;
    r.rate_hz = t.spec.rate_hz;
    r.budget_us = t.spec.budget_us;
    r.runs = t.stats->runs.load(std::memory_order_relaxed);
    r.overruns = t.stats->overruns.load(std::memory_order_relaxed);
    r.missed = t.stats->missed.load(std::memory_order_relaxed);
    r.exec = t.stats->exec.summary();
    r.jitter = t.stats->jitter.summary();
    out.push_back(std::move(r));
  }
  return out;
}

std::string Scheduler::report() const {
  std::string s;
  char line[256];
  std::snprintf(line, sizeof line, "%-16s %8s %10s %10s %10s %10s %10s %12s %9s %8s\n", "task",
                "rate[Hz]", "budget[us]", "runs", "exec p50", "exec p99", "exec max", "jitter p99",
                "overruns", "missed");
  s += line;
  auto us = [](std::int64_t ns) { return static_cast<double>(ns) / 1000.0; };
  for (const TaskReport& r : reports()) {
    char rate[16];
    if (r.rate_hz > 0) {
      std::snprintf(rate, sizeof rate, "%g", r.rate_hz);
    } else {
      std::snprintf(rate, sizeof rate, "event");
    }
    std::snprintf(line, sizeof line,
                  "%-16s %8s %10" PRId64 " %10" PRIu64 " %10.1f %10.1f %10.1f %12.1f %9" PRIu64
                  " %8" PRIu64 "\n",
                  r.name.c_str(), rate, r.budget_us, r.runs, us(r.exec.p50_ns), us(r.exec.p99_ns),
                  us(r.exec.max_ns), us(r.jitter.p99_ns), r.overruns, r.missed);
    s += line;
  }
  s += "(exec and jitter in us; jitter = actual start - ideal start)\n";
  return s;
}

}  // namespace storey::rt
