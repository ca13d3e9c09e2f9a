#include "lockstep/bridge.h"

#include <poll.h>

#include <algorithm>

#include <fmt/core.h>

#include "rths/handshake_t.hpp"
#include "rths/repair_t.hpp"

namespace rths::lockstep {

BridgedChannels::BridgedChannels(const std::string& udpm_url, const std::vector<std::string>& external_roles,
                                 const Wiring& wiring)
    : external_(external_roles) {
  if (IsPortPerChannel(udpm_url)) {
    error_ = fmt::format("{}: a mixed run bridges the external participants on one udpm port "
                         "(port_per_channel is for all-udpm runs)",
                         udpm_url);
    return;
  }
  outer_ = std::make_unique<lcm::LCM>(udpm_url);
  if (!outer_->good()) {
    error_ = fmt::format("cannot open LCM on {} (is there a multicast route? {})", udpm_url, CheckMulticastRoute());
    return;
  }
  out_[PortOffset(kChHandshake)] = in_[PortOffset(kChHandshake)] = true;
  out_[PortOffset(kChRepair)] = in_[PortOffset(kChRepair)] = true;
  for (const std::string& role : external_roles) {
    const ResolvedRole& r = wiring.Of(role);
    for (int c = kDesired; c < kChannelCodes; ++c) {
      if (r.reads[c]) out_[PortOffset(ChannelName(static_cast<std::int8_t>(c)))] = true;
    }
    in_[PortOffset(ChannelName(r.row->answer))] = true;
  }
  for (std::size_t i = 0; i < kPortChannels.size(); ++i) {
    if (in_[i]) outer_->subscribe(kPortChannels[i], &BridgedChannels::OnOuter, this);
  }
}

BridgedChannels::~BridgedChannels() = default;

bool BridgedChannels::Subscribe(const char* channel, Callback callback, void* context, Wake wake) {
  if (!inner_.Subscribe(channel, callback, context, wake)) {
    error_ = inner_.error();
    return false;
  }
  return true;
}

int BridgedChannels::Publish(const char* channel, const void* data, unsigned size) {
  const int i = PortOffset(channel);
  if (i < 0) return -1;
  if (inner_.Publish(channel, data, size) != 0) return -1;
  if (!out_[i]) return 0;
  ++sent_out_;
  return outer_->publish(channel, data, size);
}

void BridgedChannels::OnOuter(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  // Handshake and repair messages travel both ways: take in only those of an external role (our
  // own come back to us by multicast loopback).
  if (channel == kChHandshake || channel == kChRepair) {
    std::string sender;
    if (channel == kChHandshake) {
      rths::handshake_t h;
      if (h.decode(rbuf->data, 0, rbuf->data_size) < 0) return;
      sender = h.participant;
    } else {
      rths::repair_t r;
      if (r.decode(rbuf->data, 0, rbuf->data_size) < 0) return;
      sender = r.participant;
    }
    if (std::find(external_.begin(), external_.end(), sender) == external_.end()) return;
  }
  ++taken_in_;
  inner_.Publish(channel.c_str(), rbuf->data, rbuf->data_size);
}

int BridgedChannels::DrainOuter(int timeout_ms) {
  pollfd fd{outer_->getFileno(), POLLIN, 0};
  int n = 0;
  for (int wait = timeout_ms; n < 64; wait = 0) {
    const int ready = ::poll(&fd, 1, wait);
    if (ready < 0) return -1;  // errno set (EINTR: a signal)
    if (ready == 0) break;
    if (outer_->handle() != 0) return -1;
    ++n;
  }
  return n;
}

int BridgedChannels::HandleTimeout(int timeout_ms) {
  if (DrainOuter(inner_.queued() > 0 ? 0 : timeout_ms) < 0) return -1;
  return inner_.HandleTimeout(0);
}

}  // namespace rths::lockstep
