#include "lockstep/protocol.h"

#include <random>

namespace rths::lockstep {

const char* ChannelName(std::int8_t code) {
  switch (code) {
    case kDesired: return kChDesired;
    case kCommand: return kChCommand;
    case kMeasured: return kChMeasured;
    case kCurrent: return kChCurrent;
    case kAck: return kChAck;
    default: return "";
  }
}

std::int64_t NewRunId() {
  std::random_device rd;
  return static_cast<std::int64_t>(((std::uint64_t{rd()} << 32) ^ rd()) & 0x3fffffffffffffffULL) | 1;
}

bool PeekRunAndStep(const std::uint8_t* data, std::size_t size, std::int64_t* run_id, std::int64_t* k) {
  if (size < 24) return false;
  auto be64 = [](const std::uint8_t* p) {
    std::uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v = (v << 8) | p[i];
    return static_cast<std::int64_t>(v);
  };
  *run_id = be64(data + 8);
  *k = be64(data + 16);
  return true;
}

}  // namespace rths::lockstep
