#include "monitor/listener.h"

#include <poll.h>

#include <cstring>

#include <fmt/format.h>

#include "core/error.h"
#include "lockstep/abort.h"
#include "lockstep/protocol.h"
#include "lockstep/transport.h"
#include "rths/command_t.hpp"
#include "rths/desired_t.hpp"
#include "rths/handshake_t.hpp"
#include "rths/measured_t.hpp"

namespace rths::monitor {
namespace {

constexpr const char* kChannels[] = {lockstep::kChHandshake, lockstep::kChDesired, lockstep::kChCommand,
                                     lockstep::kChMeasured};

template <class Msg>
bool Decode(const lcm::ReceiveBuffer* rbuf, Msg* msg) {
  return msg->decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) >= 0;
}

}  // namespace

Listener::Listener(const std::string& url, LiveView* view) : url_(url), view_(view) {
  std::string why;
  const auto parsed = lockstep::UdpmUrl::Parse(url, &why);
  if (!parsed) throw Error("", fmt::format("--lcm-url {}: {}", url, why));
  // One LCM instance per port: the run's port, or each channel's own.
  std::vector<std::string> urls;
  if (parsed->port_per_channel) {
    for (const char* ch : kChannels) urls.push_back(parsed->ChannelUrl(ch));
  } else {
    urls.push_back(parsed->ChannelUrl(lockstep::kChHandshake));
  }
  for (std::size_t n = 0; n < urls.size(); ++n) {
    auto lcm = std::make_unique<lcm::LCM>(urls[n]);
    if (!lcm->good()) {
      throw Error("", fmt::format("cannot listen on {} (is there a multicast route? ip route add 224.0.0.0/4 dev lo)",
                                  urls[n]));
    }
    if (urls.size() == 1) {
      for (const char* ch : kChannels) lcm->subscribe(ch, &Listener::OnMessage, this);
    } else {
      lcm->subscribe(kChannels[n], &Listener::OnMessage, this);
    }
    lcms_.push_back(std::move(lcm));
  }
}

Listener::~Listener() { Stop(); }

void Listener::Start() {
  if (thread_.joinable()) return;
  stop_ = false;
  thread_ = std::thread([this] { Loop(); });
}

void Listener::Stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void Listener::Loop() {
  std::vector<pollfd> fds;
  for (const auto& lcm : lcms_) fds.push_back({lcm->getFileno(), POLLIN, 0});
  while (!stop_) {
    if (::poll(fds.data(), fds.size(), 100) <= 0) continue;
    for (std::size_t n = 0; n < fds.size(); ++n) {
      if (fds[n].revents & POLLIN) lcms_[n]->handle();
    }
  }
}

void Listener::OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  const auto now = WallClock::now();
  if (channel == lockstep::kChMeasured) {
    rths::measured_t m;
    if (Decode(rbuf, &m)) view_->OnMeasured(m.run_id, m.k, m.y_mm, m.f_kN, m.current_A, now);
  } else if (channel == lockstep::kChDesired) {
    rths::desired_t d;
    if (Decode(rbuf, &d)) view_->OnDesired(d.run_id, d.k, d.r_mm, now);
  } else if (channel == lockstep::kChCommand) {
    rths::command_t c;
    if (Decode(rbuf, &c)) view_->OnCommand(c.run_id, c.k, c.u_mm);
  } else if (channel == lockstep::kChHandshake) {
    rths::handshake_t h;
    if (Decode(rbuf, &h)) view_->OnHandshake(h.run_id, h.phase, h.participant, h.n_steps, h.dt_s, h.reason);
  }
}

std::string Listener::Abort(const std::string& reason) {
  const LiveStatus st = view_->Status();
  if (st.run_id == 0) return "no run heard on " + url_ + " yet";
  if (st.phase == "completed" || st.phase == "aborted") return "the run has already ended (" + st.phase + ")";
  if (!lockstep::BroadcastAbort(url_, st.run_id, "monitor", reason, st.last_k + 1)) {
    return "could not open " + url_ + " to send ABORT";
  }
  return "";
}

}  // namespace rths::monitor
