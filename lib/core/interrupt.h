#pragma once
/// @file The process's interrupt request: Ctrl-C or SIGTERM, as a tool's signal handler records it
/// (RequestInterrupt is async-signal-safe). Work that is not a run, such as drawing a study's
/// figures, asks InterruptRequested() and stops with rths::Interrupted, so an interrupt at any
/// stage is an interrupt (exit 130 and the resume line), never a failure of whatever it cut short.
#include <csignal>

namespace rths {

/// The flag itself, for the code that takes a `volatile std::sig_atomic_t*` (a batch's stop).
volatile std::sig_atomic_t* InterruptFlag();
/// From a signal handler: the process is asked to stop.
inline void RequestInterrupt() { *InterruptFlag() = 1; }
inline bool InterruptRequested() { return *InterruptFlag() != 0; }

}  // namespace rths
