#pragma once
/// @file A helper thread that must never compete with the step: the logger's (io::SignalsCsvWriter
/// formats rows in one, io::MappedLogFile pre-faults the log's next pages in another).
#include <pthread.h>

namespace rths::io {

/// Starts `run(arg)` on a new thread under the normal scheduler (SCHED_OTHER, whatever the calling
/// thread runs under: a paced run's SCHED_FIFO is for the step) with a 256 kB stack (a paced run's
/// mlockall(MCL_FUTURE) locks all of it). False if the thread could not be created.
bool StartBackgroundThread(pthread_t* thread, void* (*run)(void*), void* arg);

/// nanosleep for `us` microseconds, resumed after a signal.
void SleepMicros(long us);

}  // namespace rths::io
