#include "lockstep/bridge.h"

#include <algorithm>
#include <cstring>
#include <optional>

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
  std::string why;
  const std::optional<UdpmUrl> url = UdpmUrl::Parse(udpm_url, &why);
  if (!url) {
    error_ = why;
    return;
  }
  outer_ = std::make_unique<UdpmChannels>(*url);
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
    if (!in_[i] || !outer_->good()) continue;
    inlets_[i] = {this, static_cast<int>(i)};
    outer_->Subscribe(kPortChannels[i], [](void* context, const lcm::ReceiveBuffer* rbuf) {
      const auto* inlet = static_cast<const Inlet*>(context);
      inlet->bridge->OnOuter(inlet->channel, rbuf);
    }, &inlets_[i]);
  }
  if (!outer_->good()) {
    error_ = fmt::format("cannot open {}: {} (is there a multicast route? {})", udpm_url, outer_->error(),
                         CheckMulticastRoute());
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
  return outer_->Publish(channel, data, size);
}

void BridgedChannels::OnOuter(int channel, const lcm::ReceiveBuffer* rbuf) {
  const char* name = kPortChannels[static_cast<std::size_t>(channel)];
  // Handshake and repair messages travel both ways: take in only those of an external role (our
  // own come back to us by multicast loopback). They are few per run: decoding them may allocate.
  const bool handshake = std::strcmp(name, kChHandshake) == 0;
  if (handshake || std::strcmp(name, kChRepair) == 0) {
    std::string sender;
    if (handshake) {
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
  inner_.Publish(name, rbuf->data, rbuf->data_size);
}

int BridgedChannels::HandleTimeout(int timeout_ms) {
  if (outer_->HandleTimeout(inner_.queued() > 0 ? 0 : timeout_ms) < 0) return -1;
  return inner_.HandleTimeout(0);
}

}  // namespace rths::lockstep
