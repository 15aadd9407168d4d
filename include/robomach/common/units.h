#pragma once

// Unit conversions. Inside the library everything is SI and radians; these
// helpers are used once, at the file and command-line boundary (io, apps).

namespace robomach {

inline constexpr double kPi = 3.14159265358979323846;
/// Standard gravity [m/s^2]; formats.md §2 defines the rope load with it.
inline constexpr double kStandardGravity = 9.80665;

constexpr double DegToRad(double deg) { return deg * (kPi / 180.0); }
constexpr double RadToDeg(double rad) { return rad * (180.0 / kPi); }
constexpr double RpmToRadPerSec(double rpm) { return rpm * (2.0 * kPi / 60.0); }
constexpr double RadPerSecToRpm(double w) { return w * (60.0 / (2.0 * kPi)); }
constexpr double HzToRadPerSec(double hz) { return hz * 2.0 * kPi; }
constexpr double RadPerSecToHz(double w) { return w / (2.0 * kPi); }
constexpr double MmToM(double mm) { return mm * 1e-3; }
constexpr double MToMm(double m) { return m * 1e3; }

}  // namespace robomach
