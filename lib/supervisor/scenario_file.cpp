#include "supervisor/scenario_file.h"

#include <fstream>

#include "core/error.h"

namespace rths::supervisor {

scenario::Scenario WriteScenarioFile(const std::filesystem::path& file, const std::string& header,
                                     const scenario::Scenario& s) {
  {
    std::ofstream out(file, std::ios::binary);
    if (!(out << "# " << header << "\n" << scenario::ToToml(s)) || !out.flush()) {
      throw Error(file.string(), "cannot write the scenario (disk full?)");
    }
  }
  scenario::Scenario loaded = scenario::LoadScenario(file.string());
  loaded.realtime.enabled = s.realtime.enabled;
  return loaded;
}

}  // namespace rths::supervisor
