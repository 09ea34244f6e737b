// ImpostorData: the one-quad impostor, package chunk "impostor": the cheapest representation
// of a tree (the Forest's far level, the speed floor of `treelod bench`). The baker is
// ImpostorBaker.h, the GPU side ImpostorResources::getGpu and materials/TreeLodImpostor.*.
//
// ---- The quad ---------------------------------------------------------------------------
// A rectangle in the tree's local x-y plane, metres: x in [-halfWidth, halfWidth], y in
// [bottom, top], z = 0. It is drawn turned about the local +Y axis through the origin so that
// its +Z side faces the camera (a cylindrical billboard: the trunk stays upright; seen from
// high above, the quad foreshortens, its known limit). The textures are the tree seen from +Z
// (looking along -Z), orthographic, framing the quad exactly: u = 0..1 from x = -halfWidth to
// +halfWidth, v = 0..1 from y = top down to bottom (rows top to bottom, as every TreeLod
// texture).
//
// ---- Colour texture ---------------------------------------------------------------------
// RGB = sRGB albedo (LightingSpec's albedo: material colour x texture, the back colour where
// a leaf shows its back), A = coverage (fraction of the texel the tree covers, straight
// alpha). The quad is alpha-tested at alphaCutoff. Transparent texels carry the colour of
// their covered neighbours (bled), so filtering never pulls in a dark fringe; mips keep the
// covered fraction of level 0 (buildMipChain, Castaño 2010).
//
// ---- Normal texture ---------------------------------------------------------------------
// The tree's lighting: R, G = x, y of the shading normal in the quad frame (x right, y up,
// z towards the viewer), encoded n * 0.5 + 0.5; z = sqrt(max(0, 1 - x^2 - y^2)) (the
// reference's normals face the viewer); B = ambient occlusion (1 = open sky; 1 everywhere
// when baked without AO); A = 1. Mips average the normal (renormalised) and AO weighted by
// coverage; transparent texels are bled like the colour. The shader turns the normal with
// the quad and lights it as TreeLodLit.frag does:
//     colour = albedo * (ambient * ao + sun * max(0, n . sunDirection))
//
// ---- Chunk layout, formatVersion 1 (IMPOSTOR_CHUNK_FORMAT_VERSION) ---------------------
// Little-endian, GpuTexture as in ModelChunk.h:
//   u32 flags (0; others are an error), f32 halfWidth, f32 bottom, f32 top, f32 alphaCutoff
//   GpuTexture colour   RGBA8 or DXT5
//   GpuTexture normal   RGBA8 or DXT1, the colour's width, height and mip count
//   (end of chunk: trailing bytes are an error)
#pragma once

#include "TreeLod/ModelChunk.h"
#include "TreeLod/Result.h"

#include <cstdint>
#include <string>
#include <vector>

namespace TreeLod
{
    constexpr const char* IMPOSTOR_CHUNK = "impostor";
    constexpr std::uint32_t IMPOSTOR_CHUNK_FORMAT_VERSION = 1;

    struct ImpostorData
    {
        float halfWidth = 0.0f; ///< metres, > 0
        float bottom = 0.0f;    ///< metres, local y of the quad's lower edge
        float top = 0.0f;       ///< metres, > bottom
        float alphaCutoff = 0.5f; ///< in (0, 1]
        GpuTexture colour;
        GpuTexture normal;

        /// Bytes on the GPU: both textures as stored, all mips.
        std::uint64_t gpuBytes() const { return colour.data.size() + normal.data.size(); }

        /// Finite quad with positive size, cutoff in (0, 1], texture formats, sizes, mip counts
        /// and byte counts, both textures alike. `label` names the source in errors.
        Result<void> validate(const std::string& label) const;
    };

    /// Serialise in the layout above. Deterministic; does not validate (decode does).
    std::vector<std::uint8_t> encodeImpostorChunk(const ImpostorData& data);

    /// Parse and validate(); errors name `label`, "chunk 'impostor' level 0" and the element.
    Result<ImpostorData> decodeImpostorChunk(const std::vector<std::uint8_t>& bytes, const std::string& label);
}
