#include "common/haptics/precise_wait.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>

namespace sb::haptics {

namespace {
inline void cpu_relax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}
}  // namespace

void wait_until(ServoClock::time_point deadline, std::chrono::nanoseconds spin) {
  const auto wake = deadline - spin;
  if (ServoClock::now() < wake) {
    // steady_clock is CLOCK_MONOTONIC on Linux (libstdc++).
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(wake.time_since_epoch()).count();
    timespec ts{static_cast<time_t>(ns / 1000000000), static_cast<long>(ns % 1000000000)};
    while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
    }
  }
  while (ServoClock::now() < deadline) cpu_relax();
}

bool request_realtime(int priority) {
  ::prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
  sched_param sp{};
  sp.sched_priority = priority;
  if (::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &sp) == 0) return true;
  ::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), -15);  // second best, when allowed
  return false;
}

}  // namespace sb::haptics
