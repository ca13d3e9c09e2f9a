#pragma once
/// @file The maRTHS benchmark's data files (data/marths/, docs/marths.md "Files"), read once at
/// the edge into plain values (the scenario loader's [marths] table, the study).
///
/// - a matrix as CSV, one row per line, numbers only (the SAP2000 exports reference_K_N_per_m.csv
///   and reference_M_kg.csv: 29 x 29, SI);
/// - RoDeAC's initial parameters: whitespace-separated lines `theta0_1` + 4 numbers, `P0_1` + 16
///   numbers (row by row), `theta0_2`, `P0_2`; '#' starts a comment.
#include <array>
#include <string>

#include <Eigen/Core>

namespace rths::models::marths {

/// Reads a numeric CSV matrix. Throws rths::Error("path:line", ...) for a field that is not a
/// finite number or a row of another width, rths::Error("path", ...) for an unreadable or empty file.
Eigen::MatrixXd ReadMatrixCsv(const std::string& path);

/// RoDeAC's initial parameters, actuator 1 then 2.
struct RodeacInitialParameters {
  std::array<Eigen::Vector4d, 2> theta0{Eigen::Vector4d::Zero(), Eigen::Vector4d::Zero()};
  std::array<Eigen::Matrix4d, 2> P0{Eigen::Matrix4d::Zero(), Eigen::Matrix4d::Zero()};
};

/// Reads them (format in the file comment). Throws rths::Error("path:line", ...) naming the
/// entry for a missing, repeated or malformed one.
RodeacInitialParameters ReadRodeacParameters(const std::string& path);

/// The files a run of the benchmark reads (a scenario's [marths] table names them), read.
struct MarthsFiles {
  Eigen::MatrixXd K_ref, M_ref;  ///< reference_K_N_per_m.csv, reference_M_kg.csv (29 x 29, SI)
  RodeacInitialParameters rodeac;
  /// Same sizes and values (Eigen's own == requires equal sizes).
  bool operator==(const MarthsFiles& o) const;
};

}  // namespace rths::models::marths
