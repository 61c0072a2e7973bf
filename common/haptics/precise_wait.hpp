#pragma once
// Waiting for a deadline with low jitter on a shared machine: sleep (absolute, monotonic
// clock) until shortly before it, then spin. The spin costs CPU for spin_us per period; the
// sleep's wake-up latency must fit inside it. Also: asking for real-time scheduling for the
// calling thread, which keeps other threads from delaying its wake-ups.
#include <chrono>

namespace sb::haptics {

using ServoClock = std::chrono::steady_clock;

void wait_until(ServoClock::time_point deadline, std::chrono::nanoseconds spin);
// SCHED_FIFO at a low real-time priority plus a 1 us timer slack for the calling thread.
// Returns false when the system does not allow it (the thread then gets nice -15 if it may).
bool request_realtime(int priority = 20);

}  // namespace sb::haptics
