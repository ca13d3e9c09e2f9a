// libFuzzer target: io::ParseRigRecord (the CSV rig record reader) on arbitrary text
// (docs/fuzzing.md). Property: it returns a record or throws rths::Error; a record it returns
// passes ValidateRigRecord (equal lengths, finite values within the bounds, uniform time, >= 2 s).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "core/error.h"
#include "io/rig_record.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  rths::io::RigRecord rec;
  try {
    rec = rths::io::ParseRigRecord(text, "fuzz.csv");
  } catch (const rths::Error&) {
    return 0;
  }
  try {
    rths::io::ValidateRigRecord(rec, "fuzz.csv");
  } catch (const rths::Error& e) {
    std::fprintf(stderr, "ParseRigRecord accepted a record that ValidateRigRecord refuses: %s\n", e.what());
    std::abort();
  }
  return 0;
}
