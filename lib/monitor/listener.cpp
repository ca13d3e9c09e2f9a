#include "monitor/listener.h"

#include <poll.h>

#include <fmt/format.h>

#include "core/error.h"
#include "lockstep/abort.h"
#include "lockstep/live_feed.h"
#include "lockstep/protocol.h"
#include "lockstep/transport.h"
#include "rths/handshake_t.hpp"
#include "rths/monitor_t.hpp"

namespace rths::monitor {
namespace {

template <class Msg>
bool Decode(const lcm::ReceiveBuffer* rbuf, Msg* msg) {
  return msg->decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) >= 0;
}

}  // namespace

Listener::Listener(const std::string& url, LiveView* view) : url_(url), view_(view) {
  std::string why;
  const auto parsed = lockstep::UdpmUrl::Parse(url, &why);
  if (!parsed) throw Error("", fmt::format("--lcm-url {}: {}", url, why));
  // The handshake and the clock's records travel on one port (the run's, or the handshake's own).
  const std::string port_url = parsed->ChannelUrl(lockstep::kChHandshake);
  lcm_ = std::make_unique<lcm::LCM>(port_url);
  if (!lcm_->good()) {
    throw Error("", fmt::format("cannot listen on {} (is there a multicast route? ip route add 224.0.0.0/4 dev lo)",
                                port_url));
  }
  lcm_->subscribe(lockstep::kChHandshake, &Listener::OnMessage, this);
  lcm_->subscribe(lockstep::kChMonitor, &Listener::OnMessage, this);
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
  pollfd fd{lcm_->getFileno(), POLLIN, 0};
  while (!stop_) {
    if (::poll(&fd, 1, 100) > 0 && (fd.revents & POLLIN)) lcm_->handle();
  }
}

void Listener::OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  if (channel == lockstep::kChMonitor) {
    rths::monitor_t m;
    if (Decode(rbuf, &m)) view_->OnRecord(m, WallClock::now());
  } else if (channel == lockstep::kChHandshake) {
    rths::handshake_t h;
    if (Decode(rbuf, &h)) view_->OnHandshake(h.run_id, h.phase, h.participant, h.n_steps, h.dt_s, h.reason);
  }
}

std::string Listener::Abort(const std::string& reason) {
  const LiveStatus st = view_->Status();
  if (st.run_id == 0) return "no run heard on " + url_ + " yet";
  if (st.phase == "completed" || st.phase == "aborted") return "the run has already ended (" + st.phase + ")";
  if (!lockstep::BroadcastAbort(url_, st.run_id, lockstep::kMonitorSender, reason, st.last_k + 1)) {
    return "could not open " + url_ + " to send ABORT";
  }
  return "";
}

}  // namespace rths::monitor
