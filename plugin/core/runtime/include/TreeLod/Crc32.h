// CRC-32 of byte ranges: the checksum of the *.treelod header, chunk table and chunks; and
// FNV-1a 64, the hash of cache keys (bake cache, cost calibration).
//
// The IEEE 802.3 / zlib / PNG CRC-32 (reflected polynomial 0xEDB88320, initial value and
// final xor 0xFFFFFFFF): crc32("123456789") == 0xCBF43926, so any zlib can check a package.
#pragma once

#include <cstddef>
#include <cstdint>

namespace TreeLod
{
    /// CRC-32 of `size` bytes at `data` (`data` may be null when `size` is 0).
    /// Incremental: crc32(b, nb, crc32(a, na)) == crc32 of a followed by b; start with 0.
    std::uint32_t crc32(const void* data, std::size_t size, std::uint32_t previous = 0);

    /// FNV-1a 64 of `size` bytes at `data`.
    std::uint64_t fnv1a64(const void* data, std::size_t size);
}
