// Real-time setup helpers. Each returns a status instead of throwing; the caller (the
// scheduler, at start) decides whether to warn and continue.
#pragma once

#include <pthread.h>

#include <string>

namespace storey::rt {

struct SetupStatus {
  int error = 0;          // errno; 0 = applied
  const char* what = "";  // which call failed, e.g. "pthread_setschedparam"
  bool ok() const noexcept { return error == 0; }
  std::string message() const;  // "pthread_setschedparam: Operation not permitted (EPERM)"
};

// mlockall(MCL_CURRENT | MCL_FUTURE): no page faults in RT loops once memory is touched.
SetupStatus lock_memory() noexcept;
// SCHED_FIFO at priority 1..99 for `thread`.
SetupStatus set_fifo(int priority, pthread_t thread = pthread_self()) noexcept;
// Restrict `thread` to one CPU.
SetupStatus pin_cpu(int cpu, pthread_t thread = pthread_self()) noexcept;

}  // namespace storey::rt
