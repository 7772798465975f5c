#pragma once
// Peak memory is what an embedded target runs out of, and glibc's malloc keeps freed memory: its mmap
// threshold grows to the largest block freed so far (then every scan and target comes from the heap
// arenas, whose holes stay resident), each thread that allocates gets an arena of its own whose freed
// pages stay with it, and freed arena pages go back to the system only at the top.
// Both calls are no-ops where the C library is not glibc.
namespace rigcal {

/// From now on the threads share at most two malloc arenas (one per core of the 2-core target) instead of
/// one each. Call once, before the work starts its threads.
void limitHeapRetention();

/// Gives the freed pages of every malloc arena back to the system (malloc_trim): where a large piece of
/// work (a calibration's targets, the pipeline's clouds) has just been released.
void releaseFreedHeap();

}  // namespace rigcal
