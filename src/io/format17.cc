#include "robomach/io/format17.h"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace robomach::io {
namespace {

// 5^k for k <= 27 (5^27 < 2^63): 10^k / 2^s = 5^k / 2^(s - k), so that
// m * 5^k (m < 2^53) fits 128 bits for every k used below.
constexpr std::uint64_t kPow5[28] = {1ull,
                                     5ull,
                                     25ull,
                                     125ull,
                                     625ull,
                                     3125ull,
                                     15625ull,
                                     78125ull,
                                     390625ull,
                                     1953125ull,
                                     9765625ull,
                                     48828125ull,
                                     244140625ull,
                                     1220703125ull,
                                     6103515625ull,
                                     30517578125ull,
                                     152587890625ull,
                                     762939453125ull,
                                     3814697265625ull,
                                     19073486328125ull,
                                     95367431640625ull,
                                     476837158203125ull,
                                     2384185791015625ull,
                                     11920928955078125ull,
                                     59604644775390625ull,
                                     298023223876953125ull,
                                     1490116119384765625ull,
                                     7450580596923828125ull};
constexpr std::uint64_t kE16 = 10000000000000000ull, kE17 = 100000000000000000ull;

char* Fallback(double v, char* out) {
  return std::to_chars(out, out + kMaxChars17, v, std::chars_format::general, 17).ptr;
}

// round(m * 10^k / 2^s) = round(m * 5^k / 2^(s - k)) with ties to even,
// exactly (m < 2^53, 0 <= k <= 27, 1 <= s - k < 128). The result saturates
// at 10^18 (callers only accept 17 digits).
std::uint64_t ScaledRounded(std::uint64_t m, int k, int s) {
  const int shift = s - k;
  const unsigned __int128 n = static_cast<unsigned __int128>(m) * kPow5[k];
  const unsigned __int128 q = n >> shift;
  const unsigned __int128 rem = n - (q << shift);
  const unsigned __int128 half = static_cast<unsigned __int128>(1) << (shift - 1);
  unsigned __int128 r = q;
  if (rem > half || (rem == half && (q & 1))) ++r;
  return r >= static_cast<unsigned __int128>(10 * kE17) ? 10 * kE17 : static_cast<std::uint64_t>(r);
}

constexpr char kPairs[] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

// 8 decimal digits of v < 10^8 at `at`.
void Eight(std::uint32_t v, char* at) {
  for (int i = 6; i >= 0; i -= 2) {
    const std::uint32_t r = v % 100;
    v /= 100;
    at[i] = kPairs[2 * r];
    at[i + 1] = kPairs[2 * r + 1];
  }
}

}  // namespace

char* WriteDouble17(double v, char* out) {
  if (v == 0.0 || !std::isfinite(v)) return Fallback(v, out);
  const double a = std::abs(v);
  // The exact range handled here: 1e-11 <= |v| < 1e15, i.e. decimal
  // exponents exp10 in [-11, 14], k = 16 - exp10 in [2, 27]. Outside it (and
  // for the few values at a range edge) std::to_chars does it.
  if (!(a >= 1e-11 && a < 1e15)) return Fallback(v, out);
  // a = m / 2^s exactly, from the bits (a is normal in this range).
  std::uint64_t bits = 0;
  std::memcpy(&bits, &a, sizeof bits);
  const int biased = static_cast<int>(bits >> 52);
  const std::uint64_t m = (bits & ((1ull << 52) - 1)) | (1ull << 52);
  const int s = 1075 - biased;
  // floor(log10(a)), estimated from the binary exponent and one comparison
  // with a power of ten (exact for exp10 >= 0, within rounding below); the
  // loop checks it on the digits and corrects it.
  int exp10 = static_cast<int>(std::floor((biased - 1023) * 0.30102999566398120));
  static constexpr double kPow10d[29] = {1e-12, 1e-11, 1e-10, 1e-9, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3,
                                         1e-2,  1e-1,  1e0,   1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                         1e8,   1e9,   1e10,  1e11, 1e12, 1e13, 1e14, 1e15, 1e16};
  if (exp10 >= -13 && exp10 <= 15 && a >= kPow10d[exp10 + 13]) ++exp10;
  std::uint64_t digits = 0;
  for (int attempt = 0;; ++attempt) {
    const int k = 16 - exp10;
    if (attempt == 3 || k < 0 || k > 27 || s - k < 1 || s - k >= 128) return Fallback(v, out);
    digits = ScaledRounded(m, k, s);
    if (digits >= kE17) {
      ++exp10;  // log10 estimate too low, or rounding carried to 18 digits
    } else if (digits < kE16) {
      --exp10;
    } else {
      break;
    }
  }
  if (digits == kE16) {
    // Exactly 10^exp10 after rounding: a may lie just below the power (the
    // comparison above is inexact for exp10 < 0), and then %.17g writes it
    // with the exponent below unless it also rounds up to the power there.
    const int k = 17 - exp10;
    if (k > 27 || s - k < 1) return Fallback(v, out);
    const std::uint64_t below = ScaledRounded(m, k, s);
    if (below < kE17) {
      digits = below;
      --exp10;
    }
  }
  if (exp10 < -11 || exp10 > 14) return Fallback(v, out);
  // 17 digits as 1 + 8 + 8, in 32-bit arithmetic.
  char d[17];
  const auto high = static_cast<std::uint32_t>(digits / 100000000ull);  // 9 digits
  Eight(static_cast<std::uint32_t>(digits % 100000000ull), d + 9);
  Eight(high % 100000000u, d + 1);
  d[0] = static_cast<char>('0' + high / 100000000u);
  int n = 17;
  while (n > 1 && d[n - 1] == '0') --n;  // %g drops trailing zeros
  char* p = out;
  if (v < 0) *p++ = '-';
  if (exp10 < -4) {
    // d.ddde-XX, as %g writes exponents below -4 (at least two digits)
    *p++ = d[0];
    if (n > 1) {
      *p++ = '.';
      std::memcpy(p, d + 1, static_cast<size_t>(n - 1));
      p += n - 1;
    }
    *p++ = 'e';
    *p++ = '-';
    *p++ = kPairs[2 * -exp10];
    *p++ = kPairs[2 * -exp10 + 1];
  } else if (exp10 >= 0) {
    // ddd.ddd
    const int int_digits = exp10 + 1;
    for (int i = 0; i < int_digits; ++i) *p++ = i < n ? d[i] : '0';
    if (n > int_digits) {
      *p++ = '.';
      std::memcpy(p, d + int_digits, static_cast<size_t>(n - int_digits));
      p += n - int_digits;
    }
  } else {
    // 0.000ddd
    *p++ = '0';
    *p++ = '.';
    for (int i = 0; i < -exp10 - 1; ++i) *p++ = '0';
    std::memcpy(p, d, static_cast<size_t>(n));
    p += n;
  }
  return p;
}

void AppendDouble17(double v, std::string* out) {
  char buf[kMaxChars17];
  out->append(buf, WriteDouble17(v, buf));
}

}  // namespace robomach::io
