// libFuzzer target (issue #22 item 4): the polishing surface reader, a NURBS
// patch in YAML (docs/formats.md §5), and the size estimate polish-plan and
// polish-sim make of it before sampling (issue #22 found UB behind it: a
// mutated patch made the grid size NaN or huge). SampleGrid::Build itself is
// left out: its 2 x 9 x 2000 surface points take seconds in this
// instrumented build even for the project's own patches, so every input
// would be a false hang under -timeout=1. Bad input must be an InputError
// with a location; any other exception, a crash, a leak, a UB report or a
// hang is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_input_file.h"
#include "robomach/common/errors.h"
#include "robomach/io/polishing_files.h"
#include "robomach/polishing/surface_grid.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = robomach::fuzz::WriteInput(data, size, ".yaml");
  try {
    const robomach::polishing::NurbsSurface surface = robomach::io::ReadNurbsYaml(path);
    // 20 steps per iso-line (the tools use 400): a coarse size is enough
    // here; 5 mm spacing as in the shipped process files.
    const robomach::polishing::SurfaceSize z = robomach::polishing::MeasureSurface(surface, 20);
    robomach::polishing::EstimateGridPoints(z, 5e-3);
  } catch (const robomach::InputError& e) {
    robomach::fuzz::Rejected(e);
  }
  return 0;
}
