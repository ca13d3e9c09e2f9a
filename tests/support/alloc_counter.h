#pragma once
// Counts every heap allocation of this test binary (malloc, calloc, realloc, and so operator
// new), so a test can check that a per-step path allocates nothing (a rule of the code: README "Layout").
// Include in exactly one translation unit per test binary: it replaces the C allocator entry
// points with counting wrappers around glibc's own.
#include <atomic>
#include <cstddef>

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void __libc_free(void*);
}

namespace rths_test {
inline std::atomic<long> g_allocations{0};
/// Allocations made by this process so far.
inline long AllocationCount() { return g_allocations.load(std::memory_order_relaxed); }
}  // namespace rths_test

extern "C" void* malloc(std::size_t n) noexcept {
  rths_test::g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
extern "C" void* calloc(std::size_t n, std::size_t m) noexcept {
  rths_test::g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(n, m);
}
extern "C" void* realloc(void* p, std::size_t n) noexcept {
  rths_test::g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, n);
}
extern "C" void free(void* p) noexcept { __libc_free(p); }
