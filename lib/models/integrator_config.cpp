#include "models/integrator_config.h"

#include <fmt/format.h>

#include "core/error.h"

namespace rths::models {

void IntegratorConfig::Validate() const {
  const bool sub = kind == IntegratorKind::kCentralDifference || kind == IntegratorKind::kCr;
  if (sub ? (substeps < 1 || substeps > 1000) : substeps != 1)
    throw Error("substeps", fmt::format("must be {} for {} (got {})", sub ? "in [1, 1000]" : "1",
                                        NameOf(kIntegratorKindNames, kind), substeps));
  if (!(alpha >= -1.0 / 3.0 && alpha <= 0.0))
    throw Error("alpha", fmt::format("must be in [-1/3, 0] (got {})", alpha));
  if (newton_iterations < 1 || newton_iterations > 100)
    throw Error("newton_iterations", fmt::format("must be in [1, 100] (got {})", newton_iterations));
}

}  // namespace rths::models
