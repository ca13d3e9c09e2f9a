#include "participants/plant.h"

#include "participants/factory.h"

namespace rths::participants {

Plant::Plant(const scenario::Scenario& s, lockstep::RunIdentity id, lcm::LCM* lcm, lockstep::Faults faults)
    : Participant("plant", std::move(id), TimingOf(s), lcm, std::move(faults)),
      rig_(models::MakeRig(s.plant, s.run.dt_s)),
      noise_y_mm_(s.plant.noise_y_mm_rms),
      noise_f_kN_(s.plant.noise_f_kN_rms),
      noise_(signal::MakeGaussian(s.plant.noise_seed)) {
  SetAnswerChannel(lockstep::kMeasured, &cache_);
  // Only the "ideal" plant reads desired_t (r_k); the others would receive one message per step
  // for nothing (docs/lockstep.md, "Transports").
  if (rig_->TracksDesired()) {
    Subscribe(lockstep::kChDesired, [this](const lcm::ReceiveBuffer* rbuf) {
      if (!finished() && Receive(&desired_, lockstep::kDesired, rbuf) == lockstep::Put::kNew) TryStep();
    });
  }
  // The "ideal" plant wakes for desired_t k only: command_t and current_t of step k-1 were sent
  // before the clock could request step k.
  const lockstep::Wake answers = rig_->TracksDesired() ? lockstep::Wake::kLater : lockstep::Wake::kOnArrival;
  Subscribe(lockstep::kChCommand, [this](const lcm::ReceiveBuffer* rbuf) {
    if (!finished() && Receive(&command_, lockstep::kCommand, rbuf) == lockstep::Put::kNew) TryStep();
  }, answers);
  Subscribe(lockstep::kChCurrent, [this](const lcm::ReceiveBuffer* rbuf) {
    if (!finished() && Receive(&current_, lockstep::kCurrent, rbuf) == lockstep::Put::kNew) TryStep();
  }, answers);
}

void Plant::ListMissing(std::int64_t k, lockstep::WantList* out) const {
  // The barrier of step k holds measured_t k+1 when the plant answers command_t k (the clock's
  // SetBarrierIncludesNextMeasured), else ("ideal") measured_t k.
  if (next_ > k + (rig_->TracksDesired() ? 0 : 1)) return;
  if (rig_->TracksDesired() && !desired_.Get(next_)) out->Add(lockstep::kDesired, next_);
  if (next_ >= 1) {
    if (!rig_->TracksDesired() && !command_.Get(next_ - 1)) out->Add(lockstep::kCommand, next_ - 1);
    if (!current_.Get(next_ - 1)) out->Add(lockstep::kCurrent, next_ - 1);
  }
}

void Plant::Publish(std::int64_t k) {
  // Noise is drawn once per sample, in step order, so a seed gives the same readings every run.
  const double ny = noise_y_mm_ > 0.0 ? noise_y_mm_ * signal::NextGaussian(&noise_) : 0.0;
  const double nf = noise_f_kN_ > 0.0 ? noise_f_kN_ * signal::NextGaussian(&noise_) : 0.0;
  out_.run_id = id_.run_id;
  out_.k = k;
  out_.y_mm = rig_->MeasuredYMm(ny);  // y_mm() + ny; "benchmark" with its DAQ: noise before the A/D
  out_.f_kN = rig_->f_kN() + nf;
  out_.current_A = rig_->current_A();  // effective current at t_k
  Answer(lockstep::kChMeasured, &cache_, k, out_);
}

void Plant::OnGo() {
  if (rig_->TracksDesired()) {  // "ideal": measured_t 0 waits for desired_t 0 (y_0 = r_0)
    TryStep();
    return;
  }
  Guarded(0, [&] {
    Publish(0);  // at rest; no current has been commanded yet (0 A)
    next_ = 1;
  });
}

void Plant::TryStep() {
  if (rig_->TracksDesired()) {
    TryStepIdeal();
    return;
  }
  while (running() && next_ >= 1 && next_ < id_.n_steps && !Stalled(next_)) {
    const std::int64_t k = next_;
    const rths::command_t* u = command_.Get(k - 1);
    const rths::current_t* i = current_.Get(k - 1);
    if (!u || !i) return;
    bool ok = false;
    Guarded(k, [&] {
      MaybeFault(k);
      rig_->Step(u->u_mm, i->i_cmd_A);  // hold u_{k-1}, i_{k-1} over [t_{k-1}, t_k)
      Publish(k);
      ok = true;
    });
    if (!ok) return;
    ++next_;
  }
}

// plant.kind = "ideal" (docs/lockstep.md, footnote): measured_t k from desired_t k (r_k) and
// current_t k-1; the command is logged but not used. Order per step: desired -> plant -> controller.
void Plant::TryStepIdeal() {
  while (running() && next_ < id_.n_steps && !Stalled(next_)) {
    const std::int64_t k = next_;
    const rths::desired_t* r = desired_.Get(k);
    if (!r) return;
    const rths::current_t* i = nullptr;
    if (k >= 1) {
      i = current_.Get(k - 1);
      if (!i) return;
    }
    bool ok = false;
    Guarded(k, [&] {
      MaybeFault(k);
      if (k == 0) {
        rig_->StartAt(r->r_mm);  // at rest at r_0 (0 A)
      } else {
        rig_->Step(r->r_mm, i->i_cmd_A);  // x(t) from r_{k-1} to r_k over [t_{k-1}, t_k], i_{k-1}
      }
      Publish(k);
      ok = true;
    });
    if (!ok) return;
    ++next_;
  }
}

}  // namespace rths::participants
