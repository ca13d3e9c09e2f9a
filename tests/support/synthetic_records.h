#pragma once
// Shared by the diagnosis tests: a short training and test record pair from the effect blocks
// (validation/synthetic.h), the settings of docs/diagnosis.md's harness at a test's length.
#include <cstdint>
#include <functional>
#include <string>
#include <utility>

#include "validation/synthetic.h"

namespace rths_test {

/// Record maker: validation::MakeRecordBlocks or MakeRecordRig.
using MakeRecordFn = rths::io::RigRecord (*)(const rths::validation::Excitation&, const rths::validation::Truth&,
                                             const std::string&);

/// Training (BLWN 0-25 Hz, 4 mm rms, `seed`) and test (BLWN 0-8 Hz, 5 mm rms, seed + 1000, noise
/// seed + 17) records of `truth`, made by `make`. `edit` changes the training excitation before the
/// test one is derived from it; `edit_test` then changes the test excitation and truth.
inline std::pair<rths::io::RigRecord, rths::io::RigRecord> Records(
    const rths::validation::Truth& truth, double duration_s = 6.0, std::uint64_t seed = 3,
    const std::function<void(rths::validation::Excitation*)>& edit = {},
    MakeRecordFn make = &rths::validation::MakeRecordBlocks,
    const std::function<void(rths::validation::Excitation*, rths::validation::Truth*)>& edit_test = {}) {
  rths::validation::Excitation tr;
  tr.duration_s = duration_s;
  tr.band_hz = 25.0;
  tr.rms_mm = 4.0;
  tr.seed = seed;
  if (edit) edit(&tr);
  rths::validation::Excitation te = tr;
  te.band_hz = 8.0;
  te.rms_mm = 5.0;
  te.seed = seed + 1000;
  rths::validation::Truth t2 = truth;
  t2.noise_seed += 17;
  if (edit_test) edit_test(&te, &t2);
  return {make(tr, truth, "train"), make(te, t2, "test")};
}

}  // namespace rths_test
