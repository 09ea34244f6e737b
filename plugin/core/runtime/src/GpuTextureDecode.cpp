// decodeGpuTexture (ModelChunk.h): BC1-BC5 blocks to RGBA8 on the CPU, for renderers that sample
// RGBA8 faster than block-compressed textures (TreeAssetManager::CompressedTextureUpload) and for
// render systems without the format. The block layouts are Microsoft's ("Texture Block
// Compression in Direct3D 11", BC1-BC5), which are the S3TC and RGTC layouts of OpenGL.
#include "TreeLod/ModelChunk.h"

#include <cstring>

namespace TreeLod
{
    namespace
    {
        std::uint32_t word16(const std::uint8_t* b) { return std::uint32_t(b[0]) | std::uint32_t(b[1]) << 8; }

        /// A 5:6:5 colour widened to 8 bits a channel (bit replication).
        void unpack565(std::uint32_t c, std::uint8_t* rgb)
        {
            const std::uint32_t r = (c >> 11) & 31u, g = (c >> 5) & 63u, b = c & 31u;
            rgb[0] = std::uint8_t(r << 3 | r >> 2);
            rgb[1] = std::uint8_t(g << 2 | g >> 4);
            rgb[2] = std::uint8_t(b << 3 | b >> 2);
        }

        /// A BC1 colour block (8 bytes) into the 16 texels of `out` (RGBA, row-major 4x4). With
        /// `allowTransparent` (BC1 itself) c0 <= c1 selects three colours and transparent black;
        /// the colour block of BC3 is always four colours.
        void decodeColourBlock(const std::uint8_t* block, bool allowTransparent, std::uint8_t (&out)[16][4])
        {
            const std::uint32_t c0 = word16(block), c1 = word16(block + 2);
            std::uint8_t palette[4][4] = {};
            unpack565(c0, palette[0]);
            unpack565(c1, palette[1]);
            palette[0][3] = palette[1][3] = 255;
            const bool four = !allowTransparent || c0 > c1;
            for (int ch = 0; ch < 3; ++ch)
            {
                const int a = palette[0][ch], b = palette[1][ch];
                palette[2][ch] = std::uint8_t(four ? (2 * a + b) / 3 : (a + b) / 2);
                palette[3][ch] = std::uint8_t(four ? (a + 2 * b) / 3 : 0);
            }
            palette[2][3] = 255;
            palette[3][3] = four ? 255 : 0;
            std::uint32_t indices = std::uint32_t(block[4]) | std::uint32_t(block[5]) << 8 |
                                    std::uint32_t(block[6]) << 16 | std::uint32_t(block[7]) << 24;
            for (int t = 0; t < 16; ++t, indices >>= 2)
                std::memcpy(out[t], palette[indices & 3u], 4);
        }

        /// A BC4 block (8 bytes: two endpoints, sixteen 3-bit indices) into channel `channel`
        /// of the 16 texels of `out`.
        void decodeChannelBlock(const std::uint8_t* block, int channel, std::uint8_t (&out)[16][4])
        {
            const int a0 = block[0], a1 = block[1];
            int palette[8] = {a0, a1};
            if (a0 > a1)
                for (int i = 1; i < 7; ++i)
                    palette[i + 1] = ((7 - i) * a0 + i * a1) / 7;
            else
            {
                for (int i = 1; i < 5; ++i)
                    palette[i + 1] = ((5 - i) * a0 + i * a1) / 5;
                palette[6] = 0;
                palette[7] = 255;
            }
            std::uint64_t indices = 0;
            for (int i = 0; i < 6; ++i)
                indices |= std::uint64_t(block[2 + i]) << (8 * i);
            for (int t = 0; t < 16; ++t, indices >>= 3)
                out[t][channel] = std::uint8_t(palette[indices & 7u]);
        }

        /// One 4x4 block of `format` (at `block`) as RGBA texels.
        void decodeBlock(GpuTextureFormat format, const std::uint8_t* block, std::uint8_t (&out)[16][4])
        {
            switch (format)
            {
            case GpuTextureFormat::DXT1:
                decodeColourBlock(block, true, out);
                break;
            case GpuTextureFormat::DXT5:
                decodeColourBlock(block + 8, false, out);
                decodeChannelBlock(block, 3, out);
                break;
            case GpuTextureFormat::BC4:
            case GpuTextureFormat::BC5:
                for (auto& t : out)
                    t[0] = t[1] = t[2] = 0, t[3] = 255;
                decodeChannelBlock(block, 0, out);
                if (format == GpuTextureFormat::BC5)
                    decodeChannelBlock(block + 8, 1, out);
                break;
            case GpuTextureFormat::RGBA8:
                break;
            }
        }
    }

    GpuTexture decodeGpuTexture(const GpuTexture& src)
    {
        if (!isBlockCompressed(src.format))
            return src;
        GpuTexture out;
        out.name = src.name;
        out.format = GpuTextureFormat::RGBA8;
        out.width = src.width;
        out.height = src.height;
        out.mipCount = src.mipCount;
        out.data.resize(gpuTextureBytes(GpuTextureFormat::RGBA8, src.width, src.height, src.mipCount));
        const std::size_t blockBytes = src.mipBytes(0) / (std::size_t((src.width + 3) / 4) * ((src.height + 3) / 4));
        for (std::uint32_t mip = 0; mip < src.mipCount; ++mip)
        {
            const std::uint32_t w = src.mipWidth(mip), h = src.mipHeight(mip);
            const std::uint8_t* blocks = src.data.data() + src.mipOffset(mip);
            std::uint8_t* texels = out.data.data() + out.mipOffset(mip);
            for (std::uint32_t by = 0; by < (h + 3) / 4; ++by)
                for (std::uint32_t bx = 0; bx < (w + 3) / 4; ++bx, blocks += blockBytes)
                {
                    std::uint8_t block[16][4];
                    decodeBlock(src.format, blocks, block);
                    for (std::uint32_t y = 4 * by; y < h && y < 4 * by + 4; ++y)
                        for (std::uint32_t x = 4 * bx; x < w && x < 4 * bx + 4; ++x)
                            std::memcpy(texels + (std::size_t(y) * w + x) * 4, block[(y - 4 * by) * 4 + (x - 4 * bx)], 4);
                }
        }
        return out;
    }
}
