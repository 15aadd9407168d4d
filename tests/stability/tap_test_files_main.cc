// Writes issue #18's synthetic tap test (tests/tap_test_synth.h) as the
// formats.md §3 CSV files the stability-lobes tests read:
//   tap_xxyy.csv   Hxx = Hyy (posture P1)
//   tap_zz.csv     the same FRF as the only one, Hzz (posture T1)
//   tap_cross.csv  a tool whose one mode family moves along (1, 1, 0)/√2:
//                  Hxx = Hyy = Hxy = Hyx = H/2 (posture C1)
// Usage: tap_test_files OUT_DIR
#include <iostream>
#include <string>

#include "tap_test_synth.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: tap_test_files OUT_DIR\n";
    return 64;
  }
  const std::string dir = argv[1];
  using robomach::testing::WriteTapTestCsv;
  robomach::testing::TapTest t = robomach::testing::MakeTapTest();
  WriteTapTestCsv(dir + "/tap_xxyy.csv", t, "P1", {"xx", "yy"});
  WriteTapTestCsv(dir + "/tap_zz.csv", t, "T1", {"zz"});
  t.measured *= 0.5;
  WriteTapTestCsv(dir + "/tap_cross.csv", t, "C1", {"xx", "xy", "yx", "yy"});
  return 0;
}
