#include <algorithm>
#include <cmath>

#include "diagnosis/diagnosis.h"

namespace rths::diagnosis {

std::vector<SensorFault> FindFlatSensors(const io::RigRecord& r, double min_s) {
  std::vector<SensorFault> out;
  const std::size_t n = r.size();
  const auto min_n = static_cast<std::size_t>(std::ceil(min_s / r.dt_s));
  auto scan = [&](const char* channel, const std::vector<double>& x, const std::vector<double>& drive) {
    // A channel constant throughout was not connected (a force column of zeros): said elsewhere.
    if (n == 0 || std::all_of(x.begin(), x.end(), [&](double v) { return v == x[0]; })) return;
    std::size_t a = 0;
    for (std::size_t k = 1; k <= n; ++k) {
      if (k < n && x[k] == x[a]) continue;
      if (k - a >= min_n && k - a >= 2) {  // x[a .. k-1] all equal: does the drive move meanwhile?
        const auto [lo, hi] = std::minmax_element(drive.begin() + static_cast<std::ptrdiff_t>(a),
                                                  drive.begin() + static_cast<std::ptrdiff_t>(k));
        if (*hi > *lo) out.push_back({r.source, channel, r.t_s[a], r.t_s[k - 1], x[a]});
      }
      a = k;
    }
  };
  if (r.y_mm.size() == n && r.u_mm.size() == n) scan("y", r.y_mm, r.u_mm);
  if (r.f_kN.size() == n && r.y_mm.size() == n) scan("f", r.f_kN, r.y_mm);
  return out;
}

}  // namespace rths::diagnosis
