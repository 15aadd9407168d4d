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

#if defined(__SANITIZE_ADDRESS__)
#define ROBOMACH_FUZZ_LSAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ROBOMACH_FUZZ_LSAN 1
#endif
#endif
#if ROBOMACH_FUZZ_LSAN
#include <sanitizer/lsan_interface.h>
#endif

#include "fuzz_input_file.h"
#include "robomach/common/errors.h"
#include "robomach/io/cad_face.h"

// OpenCASCADE sets up its STEP and IGES readers once per process, on first
// use, and loses some of that memory (~3 KB in STEPControl_Controller::Init,
// the same for one read or a thousand; its stack is cut short in the
// uninstrumented library, so a suppression cannot name it). A STEP and an
// IGES read before the first input, with LeakSanitizer off, keep that out of
// libFuzzer's leak check (which reports every unreachable block, whenever
// it was allocated).
extern "C" int LLVMFuzzerInitialize(int*, char***) {
#if ROBOMACH_FUZZ_LSAN
  __lsan_disable();
#endif
  robomach::io::ReadCadFace(ROBOMACH_SOURCE_DIR "/config/polishing/blade.step", 0);
  try {
    const char kNotIges[] = "not an IGES file\n";
    robomach::io::ReadCadFace(robomach::fuzz::WriteInput(reinterpret_cast<const uint8_t*>(kNotIges),
                                                         sizeof(kNotIges) - 1, ".igs"),
                              0);
  } catch (const robomach::InputError& e) {
    robomach::fuzz::Rejected(e);
  }
#if ROBOMACH_FUZZ_LSAN
  __lsan_enable();
#endif
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  constexpr size_t kMaxBytes = 16 * 1024;
  if (size > kMaxBytes) return 0;
  const bool step = size >= 12 && std::memcmp(data, "ISO-10303-21", 12) == 0;
  const std::string path = robomach::fuzz::WriteInput(data, size, step ? ".step" : ".igs");
  try {
    // Face 0 = the largest face: every face is converted once.
    robomach::io::ReadCadFace(path, 0);
  } catch (const robomach::InputError& e) {
    robomach::fuzz::Rejected(e);
  }
  return 0;
}
