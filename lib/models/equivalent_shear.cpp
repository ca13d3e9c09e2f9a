#include "models/equivalent_shear.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "core/error.h"

namespace rths::models {

std::vector<double> FirstModeStoryStiffness(const Eigen::MatrixXd& M, const Eigen::MatrixXd& K) {
  const Eigen::Index n = K.rows();
  if (n < 1 || K.cols() != n || M.rows() != n || M.cols() != n)
    throw Error("K", fmt::format("M ({}x{}) and K ({}x{}) must be square and of one size", M.rows(), M.cols(),
                                 K.rows(), K.cols()));
  Eigen::LLT<Eigen::MatrixXd> llt(K);
  if (llt.info() != Eigen::Success) throw Error("K", "must be positive definite");
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(K, M);
  if (eig.info() != Eigen::Success) throw Error("K", "the eigenproblem K phi = w^2 M phi did not converge");
  Eigen::VectorXd phi = eig.eigenvectors().col(0);  // ascending: the lowest mode
  if (phi(n - 1) < 0.0) phi = -phi;                  // the top floor positive
  const Eigen::VectorXd F = M * phi;
  const Eigen::VectorXd x = llt.solve(F);
  std::vector<double> k(static_cast<std::size_t>(n));
  double shear = 0.0;
  for (Eigen::Index i = n - 1; i >= 0; --i) {
    shear += F(i);
    const double drift = x(i) - (i > 0 ? x(i - 1) : 0.0);
    if (!(shear > 0.0) || !(drift > 0.0))
      throw Error("K", fmt::format("story {}: the first mode's shear ({:g}) or drift ({:g}) is not positive: "
                                   "no shear building has this first mode",
                                   i + 1, shear, drift));
    k[static_cast<std::size_t>(i)] = shear / drift;
  }
  return k;
}

}  // namespace rths::models
