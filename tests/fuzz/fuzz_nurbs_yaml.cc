// libFuzzer target (issue #22 item 4): the polishing surface reader, a NURBS
// patch in YAML (docs/formats.md §5), and the sample grid polish-plan and
// polish-sim build from it at once (issue #22 found UB there: a mutated patch
// made the grid size NaN or huge). Bad input must be an InputError with a
// location (std::domain_error for a patch the grid cannot sample, as the
// tools report it); any other exception, a crash, a leak, a UB report or a
// hang is a finding.
#include <cstddef>
#include <cstdint>
#include <stdexcept>

#include "fuzz_input_file.h"
#include "robomach/common/errors.h"
#include "robomach/io/polishing_files.h"
#include "robomach/polishing/surface_grid.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = robomach::fuzz::WriteInput(data, size, ".yaml");
  try {
    const robomach::polishing::NurbsSurface surface = robomach::io::ReadNurbsYaml(path);
    // 5 mm spacing, 2 mm margin, at most 20000 points: small enough that an
    // input is over in well under the 1 s hang limit.
    robomach::polishing::SampleGrid::Build(surface, 5e-3, 2e-3, false, 20000);
  } catch (const robomach::InputError&) {
  } catch (const std::domain_error&) {
  }
  return 0;
}
