// libFuzzer target (issue #22 item 4): the raw quadrature capture
// (docs/formats.md §8.2) as axis-decode reads it: little-endian uint16
// words through machine::QuadratureDecoder. The input's first two bytes
// choose the decoder (axes = 1 + b0 % 8, glitch filter = b1 % 8 samples,
// block size = 1 + b0 / 8 words); the rest is the capture (an odd last byte
// is dropped: axis-decode rejects odd sizes before decoding). Besides
// crashes, leaks, UB and hangs, a finding is a result that depends on how
// the capture is split into blocks (the decoder promises it does not).
#include <cstddef>
#include <cstdint>
#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "robomach/machine/quadrature_decoder.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 2) return 0;
  robomach::machine::QuadratureOptions options;
  options.num_axes = 1 + data[0] % robomach::machine::kMaxQuadratureAxes;
  options.glitch_filter_samples = data[1] % 8;
  const size_t block = 1 + data[0] / 8;
  std::vector<std::uint16_t> words((size - 2) / 2);
  for (size_t i = 0; i < words.size(); ++i) {
    words[i] = static_cast<std::uint16_t>(data[2 + 2 * i] | (data[3 + 2 * i] << 8));
  }
  robomach::machine::QuadratureDecoder whole(options), blocks(options);
  whole.Decode(words.data(), words.size());
  for (size_t at = 0; at < words.size(); at += block) {
    blocks.Decode(words.data() + at, std::min(block, words.size() - at));
  }
  if (whole.samples() != static_cast<std::int64_t>(words.size()) || blocks.samples() != whole.samples()) std::abort();
  for (int a = 0; a < options.num_axes; ++a) {
    if (whole.counts()[a] != blocks.counts()[a] || whole.error_events()[a] != blocks.error_events()[a]) std::abort();
  }
  return 0;
}
