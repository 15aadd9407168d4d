// libFuzzer target (issue #22 item 4): one face of a STEP or IGES file as a
// polishing surface (io/cad_face.h, docs/formats.md §5), read with
// OpenCASCADE. An input starting "ISO-10303-21" is read as .step, anything
// else as .igs. Time-bounded: inputs over 16 KB are skipped (the project's
// STEP files are 5-7 KB; OpenCASCADE's reading time grows with the file) and
// libFuzzer's -timeout=1 makes any input slower than a second a finding.
// Bad input must be an InputError naming the file; any other exception, a
// crash, a leak, a UB report or a hang is a finding.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "fuzz_input_file.h"
#include "robomach/common/errors.h"
#include "robomach/io/cad_face.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  constexpr size_t kMaxBytes = 16 * 1024;
  if (size > kMaxBytes) return 0;
  const bool step = size >= 12 && std::memcmp(data, "ISO-10303-21", 12) == 0;
  const std::string path = robomach::fuzz::WriteInput(data, size, step ? ".step" : ".igs");
  try {
    // Face 0 = the largest face: every face is converted once.
    robomach::io::ReadCadFace(path, 0);
  } catch (const robomach::InputError&) {
  }
  return 0;
}
