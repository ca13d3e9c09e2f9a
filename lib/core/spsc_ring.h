#pragma once
/// @file A bounded single-producer single-consumer queue, lock-free: one thread pushes, one other
/// thread pops, neither ever waits for the other (a full ring refuses the push, an empty one the
/// pop). Storage is allocated once, at construction; pushing and popping allocate nothing.
#include <atomic>
#include <cstddef>
#include <vector>

namespace rths {

template <class T>
class SpscRing {
 public:
  /// Holds up to `capacity` items (rounded up to a power of two, at least 2).
  explicit SpscRing(std::size_t capacity) : slots_(RoundUp(capacity)), mask_(slots_.size() - 1) {}
  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  /// Producer: copies `item` in; false (nothing changed) if the ring is full.
  bool TryPush(const T& item) {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_.load(std::memory_order_acquire) == slots_.size()) return false;
    slots_[head & mask_] = item;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }
  /// Consumer: moves the oldest item into `*out`; false if the ring is empty.
  bool TryPop(T* out) {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) return false;
    *out = slots_[tail & mask_];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }
  std::size_t capacity() const { return slots_.size(); }

 private:
  static std::size_t RoundUp(std::size_t n) {
    std::size_t p = 2;
    while (p < n) p *= 2;
    return p;
  }
  std::vector<T> slots_;
  const std::size_t mask_;
  alignas(64) std::atomic<std::size_t> head_{0};  ///< next slot to write (producer)
  alignas(64) std::atomic<std::size_t> tail_{0};  ///< next slot to read (consumer)
};

}  // namespace rths
