#pragma once
/// @file A udpm run's UDP port: one per run (or one per channel), picked free so that runs side
/// by side on one host cannot hear each other.

namespace rths::supervisor {

/// A UDP port free right now (the kernel's ephemeral allocator). Throws rths::Error.
int FreeUdpPort();

/// A base port P with P .. P+n-1 all free for UDP (each bound once, then released), picked by
/// the kernel's ephemeral allocator and checked. Throws rths::Error.
int FreeUdpPorts(int n);

}  // namespace rths::supervisor
