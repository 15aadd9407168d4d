// nurbs_to_step IN.yaml OUT.step [comment]: writes a NURBS YAML patch
// (formats.md §5) as a one-face STEP file with OpenCASCADE. Made the STEP
// copy of config/polishing/blade.yaml (see the comment in that file); not a
// user tool, so it lives with the tests.
#include <iostream>

#include "robomach/common/errors.h"
#include "robomach/io/cad_face.h"
#include "robomach/io/polishing_files.h"

int main(int argc, char** argv) {
  if (argc < 3 || argc > 4) {
    std::cerr << "usage: nurbs_to_step IN.yaml OUT.step [comment]\n";
    return 64;
  }
  try {
    const auto s = robomach::io::ReadNurbsYaml(argv[1]);
    robomach::io::WriteStepFace(s, argv[2], argc == 4 ? argv[3] : "");
  } catch (const robomach::InputError& e) {
    std::cerr << "nurbs_to_step: " << e.what() << "\n";
    return 65;
  } catch (const std::exception& e) {
    std::cerr << "nurbs_to_step: " << e.what() << "\n";
    return 73;
  }
  return 0;
}
