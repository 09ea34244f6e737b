// CRC-32 (IEEE 802.3 polynomial, reflected) with "slicing-by-8" tables: eight table
// look-ups consume eight input bytes per step (Kounavis & Berry, "A Systematic Approach to
// Building High Performance Software-Based CRC Generators", ISCC 2005).
#include "TreeLod/Crc32.h"

#include <array>

namespace TreeLod
{
    namespace
    {
        using Tables = std::array<std::array<std::uint32_t, 256>, 8>;

        Tables makeTables()
        {
            Tables t{};
            for (std::uint32_t i = 0; i < 256; ++i)
            {
                std::uint32_t c = i;
                for (int k = 0; k < 8; ++k)
                    c = (c & 1u) ? (c >> 1) ^ 0xEDB88320u : c >> 1;
                t[0][i] = c;
            }
            // t[k][i]: CRC of byte i followed by k zero bytes.
            for (std::uint32_t i = 0; i < 256; ++i)
                for (int k = 1; k < 8; ++k)
                    t[k][i] = (t[k - 1][i] >> 8) ^ t[0][t[k - 1][i] & 0xFFu];
            return t;
        }

        const Tables& tables()
        {
            static const Tables t = makeTables();
            return t;
        }
    }

    std::uint32_t crc32(const void* data, std::size_t size, std::uint32_t previous)
    {
        const Tables& t = tables();
        const auto* p = static_cast<const std::uint8_t*>(data);
        std::uint32_t c = ~previous;
        while (size >= 8)
        {
            // Byte-wise assembly keeps this independent of host endianness and alignment.
            std::uint32_t lo = c ^ (std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 |
                                    std::uint32_t(p[3]) << 24);
            c = t[7][lo & 0xFFu] ^ t[6][(lo >> 8) & 0xFFu] ^ t[5][(lo >> 16) & 0xFFu] ^ t[4][lo >> 24] ^
                t[3][p[4]] ^ t[2][p[5]] ^ t[1][p[6]] ^ t[0][p[7]];
            p += 8;
            size -= 8;
        }
        while (size-- > 0)
            c = (c >> 8) ^ t[0][(c ^ *p++) & 0xFFu];
        return ~c;
    }

    std::uint64_t fnv1a64(const void* data, std::size_t size)
    {
        const auto* p = static_cast<const std::uint8_t*>(data);
        std::uint64_t h = 0xcbf29ce484222325ull;
        for (std::size_t i = 0; i < size; ++i)
        {
            h ^= p[i];
            h *= 0x100000001b3ull;
        }
        return h;
    }
}
