#pragma once
// LZF decompression (Marc Lehmann's liblzf format), the codec of PCL's `binary_compressed` PCD files.
// Every read and every back-reference is bounds-checked: a corrupt or hostile stream gives an error,
// never a read or write outside the buffers.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace rigcal {

/// Decompresses `in` into exactly `expected_size` bytes. Throws std::runtime_error with a one-line
/// reason (offset in the compressed stream and what is wrong) when the stream is malformed or does not
/// decompress to exactly that size.
std::vector<std::uint8_t> lzfDecompress(std::span<const std::uint8_t> in, std::size_t expected_size);

}  // namespace rigcal
