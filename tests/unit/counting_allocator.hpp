#pragma once
// Live heap bytes of the test executable: counting_allocator.cpp replaces the global
// operator new/delete of every executable it is linked into, so that a model's own account
// of its containers (stats().bytes) can be checked against what it really holds, and what an
// operation holds at its peak.
namespace sb::test {

long long live_heap_bytes();
// The most live_heap_bytes() has been since the last reset_peak_heap_bytes() (or the start).
long long peak_heap_bytes();
void reset_peak_heap_bytes();

}  // namespace sb::test
