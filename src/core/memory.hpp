// This process's resident memory, for memory limits and the run's timings.
// SPDX-License-Identifier: MIT
#pragma once

namespace terrapolis {

/// Resident memory of this process now (Linux VmRSS), MB (10^6 bytes, as the memory limits); 0 elsewhere.
double resident_mb();
/// Peak resident memory of this process so far (getrusage's ru_maxrss, kB on Linux), MB (10^6 bytes).
double peak_resident_mb();
/// Hands the heap's free pages back to the system (glibc keeps them resident after a stage frees
/// its state), so that the next stage's memory limit counts only what is in use.
void release_free_memory();
/// Under a memory limit: every block of 1 MB or more is mapped on its own and unmapped when freed.
/// glibc otherwise raises that threshold up to 32 MB after the first such block is freed, and the
/// tiles' and windows' buffers then fragment the heap: the run on New Zealand at a 170 MB limit
/// peaked at 153-172 MB, at 141 MB with this.
void map_large_blocks();

}  // namespace terrapolis
