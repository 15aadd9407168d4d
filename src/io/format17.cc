#include "robomach/io/format17.h"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace robomach::io {
namespace {

constexpr std::uint64_t kPow10[20] = {1ull,
                                      10ull,
                                      100ull,
                                      1000ull,
                                      10000ull,
                                      100000ull,
                                      1000000ull,
                                      10000000ull,
                                      100000000ull,
                                      1000000000ull,
                                      10000000000ull,
                                      100000000000ull,
                                      1000000000000ull,
                                      10000000000000ull,
                                      100000000000000ull,
                                      1000000000000000ull,
                                      10000000000000000ull,
                                      100000000000000000ull,
                                      1000000000000000000ull,
                                      10000000000000000000ull};

void Fallback(double v, std::string* out) {
  char buf[40];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 17);
  out->append(buf, r.ptr);
}

// round(m * 10^k / 2^s) with ties to even, exactly (m < 2^53, k <= 19, s < 128).
std::uint64_t ScaledRounded(std::uint64_t m, int k, int s, bool* fits) {
  const unsigned __int128 n = static_cast<unsigned __int128>(m) * kPow10[k];
  const unsigned __int128 q = s >= 128 ? 0 : n >> s;
  const unsigned __int128 rem = n - (q << s);
  const unsigned __int128 half = static_cast<unsigned __int128>(1) << (s - 1);
  unsigned __int128 r = q;
  if (rem > half || (rem == half && (q & 1))) ++r;
  *fits = r < static_cast<unsigned __int128>(kPow10[19]);
  return static_cast<std::uint64_t>(r);
}

}  // namespace

void AppendDouble17(double v, std::string* out) {
  if (v == 0.0 || !std::isfinite(v)) return Fallback(v, out);
  const double a = std::abs(v);
  // The exact range handled here: 1e-4 <= |v| < 1e15 (the decimal exponent
  // then needs k = 16 - exp10 in [2, 20) and the binary exponent a shift).
  if (!(a >= 1e-4 && a < 1e15)) return Fallback(v, out);
  // a = m / 2^s exactly, from the bits (a is normal in this range).
  std::uint64_t bits = 0;
  std::memcpy(&bits, &a, sizeof bits);
  const int biased = static_cast<int>(bits >> 52);
  const std::uint64_t m = (bits & ((1ull << 52) - 1)) | (1ull << 52);
  const int s = 1075 - biased;
  if (s <= 0 || s >= 127) return Fallback(v, out);
  // floor(log10(a)) to within one; the loop below corrects it.
  int exp10 = static_cast<int>(std::floor((biased - 1023) * 0.30102999566398120));
  // Powers of ten up to 1e22 are exact doubles: settle exp10 >= 0 here.
  static constexpr double kPow10d[17] = {1e0, 1e1, 1e2,  1e3,  1e4,  1e5,  1e6,  1e7, 1e8,
                                         1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16};
  if (exp10 >= 0 && exp10 < 16 && a >= kPow10d[exp10 + 1]) ++exp10;
  std::uint64_t digits = 0;
  for (int attempt = 0; attempt < 3; ++attempt) {
    const int k = 16 - exp10;
    if (k < 0 || k > 19) return Fallback(v, out);
    bool fits = false;
    digits = ScaledRounded(m, k, s, &fits);
    if (!fits) return Fallback(v, out);
    if (digits >= kPow10[17]) {
      ++exp10;  // log10 estimate too low, or rounding carried to 18 digits
      continue;
    }
    if (digits < kPow10[16]) {
      --exp10;
      continue;
    }
    break;
  }
  if (digits < kPow10[16] || digits >= kPow10[17]) return Fallback(v, out);
  static constexpr char kPairs[] =
      "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
      "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
      "8081828384858687888990919293949596979899";
  char d[18];
  for (int i = 16; i >= 1; i -= 2) {
    const unsigned r = static_cast<unsigned>(digits % 100);
    digits /= 100;
    d[i - 1] = kPairs[2 * r];
    d[i] = kPairs[2 * r + 1];
  }
  d[0] = static_cast<char>('0' + digits);
  int n = 17;
  while (n > 1 && d[n - 1] == '0') --n;  // %g drops trailing zeros
  if (exp10 < -4 || exp10 >= 17) return Fallback(v, out);  // not reached for the range above
  if (v < 0) out->push_back('-');
  if (exp10 >= 0) {
    // ddd.ddd
    const int int_digits = exp10 + 1;
    for (int i = 0; i < int_digits; ++i) out->push_back(i < n ? d[i] : '0');
    if (n > int_digits) {
      out->push_back('.');
      out->append(d + int_digits, d + n);
    }
  } else {
    out->append("0.");
    out->append(static_cast<size_t>(-exp10 - 1), '0');
    out->append(d, d + n);
  }
}

}  // namespace robomach::io
