// CommandForModel of ident/spencer_fit.h: the damper command a model is driven with, a small
// negative part (a DAQ's noise) taken as 0 (docs/identification.md "Negative commands").
#include <algorithm>

#include <fmt/format.h>

#include "core/error.h"
#include "ident/spencer_fit.h"

namespace rths::ident {

ModelCommand CommandForModel(const io::RigRecord& rec, bool voltage) {
  const auto raw = ControlInput(rec, voltage);
  ModelCommand c;
  c.v.assign(raw.begin(), raw.end());
  double top = 0.0;
  for (double x : c.v) {
    top = std::max(top, x);
    if (x < 0.0) {
      ++c.negatives;
      c.worst = std::min(c.worst, x);
    }
  }
  if (c.negatives == 0) return c;
  const char* unit = voltage ? "V" : "A";
  const char* column = voltage ? "v_V" : "i_A";
  const double share = static_cast<double>(c.negatives) / static_cast<double>(c.v.size());
  const std::string what = fmt::format("{} of {} samples of {} ({:.3g} %) are negative, down to {:.4g} {}", c.negatives,
                                       c.v.size(), column, 100.0 * share, c.worst, unit);
  if (share > kMaxNegativeShare || -c.worst > top)
    throw Error(RecordName(rec),
                fmt::format("{}: not noise around 0 (the rule: at most {:g} % of the samples, none below minus the "
                            "largest command {:.4g} {}); the damper's laws (Eqs. 35-39) take a command >= 0: a bipolar "
                            "command needs its magnitude in the column (docs/identification.md \"Negative commands\")",
                            what, 100.0 * kMaxNegativeShare, top, unit));
  for (double& x : c.v) x = std::max(x, 0.0);
  c.warning = fmt::format("{}: {}: taken as 0 {} (a DAQ's noise, or its anti-alias filter ringing at the command's steps)",
                          RecordName(rec), what, unit);
  return c;
}

}  // namespace rths::ident
