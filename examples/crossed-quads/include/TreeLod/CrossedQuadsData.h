// CrossedQuadsData: the crossed-quads technique, package chunk "crossed-quads": the classic far
// tree of games and forest renderers, two or three vertical textured rectangles that cross on the
// tree's trunk axis, each showing the tree as seen square-on from its side (a "cross
// billboard"). An example of the technique seam, built outside the plugin from public headers
// only (examples/crossed-quads/README.md).
//
// Where it deviates from the best practice of this project (the impostor, ImpostorData.h):
//   - no normal map: the quads are lit with their own face normal (turned to the viewer by the
//     leaf shader), so the crown has one brightness per quad, not the tree's shading;
//   - no ambient occlusion baked in; colour is the albedo only;
//   - the quads do not turn to the camera: seen between two quads, or from above, the tree
//     thins out and shows its construction (the technique's known limit).
//
// ---- The quads --------------------------------------------------------------------------
// Quad i stands at azimuth a_i (degrees, about the local +Y axis; 0 = seen from +Z as the
// impostor). Its frame: right r = (cos a, 0, -sin a), up (0, 1, 0), facing n = (sin a, 0, cos a)
// (towards the viewer the bake placed at +n). Its corners are r * s + (0, y, 0) for s in
// [left, right], y in [bottom, top] (metres, local). Its texture is the tree seen along -n,
// orthographic, framing the quad exactly: u = 0..1 from s = left to right, v = 0..1 from
// y = top down to bottom (rows top to bottom, as every TreeLod texture); texels are square.
//
// ---- Textures -----------------------------------------------------------------------------
// RGB = sRGB albedo (the reference renderer under white ambient light), A = coverage (straight
// alpha). Transparent texels carry their covered neighbours' colour (bled); mips keep the
// covered fraction of level 0 (Castaño 2010). Alpha-tested at alphaCutoff.
//
// ---- Chunk layout, formatVersion 1 (CROSSED_QUADS_CHUNK_FORMAT_VERSION) --------------------
// Little-endian, GpuTexture as in ModelChunk.h:
//   u32 flags (0; others are an error)
//   f32 alphaCutoff                      in (0, 1]
//   u32 quadCount                        1 .. CROSSED_QUADS_MAX_QUADS
//   per quad: f32 azimuth (degrees, [0, 360)), f32 left, f32 right, f32 bottom, f32 top
//   per quad: GpuTexture colour          RGBA8 or DXT5
//   (end of chunk: trailing bytes are an error)
#pragma once

#include "TreeLod/ModelChunk.h"
#include "TreeLod/Result.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace TreeLod
{
    constexpr const char* CROSSED_QUADS_CHUNK = "crossed-quads";
    constexpr std::uint32_t CROSSED_QUADS_CHUNK_FORMAT_VERSION = 1;
    constexpr std::uint32_t CROSSED_QUADS_MAX_QUADS = 8;

    struct CrossedQuad
    {
        float azimuth = 0.0f; ///< degrees in [0, 360)
        float left = 0.0f;    ///< metres along the quad's right axis, < right
        float right = 0.0f;
        float bottom = 0.0f;  ///< metres, local y, < top
        float top = 0.0f;
        GpuTexture colour;

        /// The quad's frame: right r = (cos a, 0, -sin a) and facing n = (sin a, 0, cos a).
        glm::vec3 rightAxis() const;
        glm::vec3 facing() const;
        /// The local point at `s` along the right axis and height `y`: r * s + (0, y, 0).
        glm::vec3 point(float s, float y) const { return rightAxis() * s + glm::vec3(0.0f, y, 0.0f); }
    };

    struct CrossedQuadsData
    {
        float alphaCutoff = 0.5f;      ///< in (0, 1]
        std::vector<CrossedQuad> quads; ///< 1 .. CROSSED_QUADS_MAX_QUADS

        /// Bytes on the GPU: every texture as stored, all mips.
        std::uint64_t textureBytes() const;

        /// Quad count, finite rectangles with positive size, azimuths, cutoff, and per texture its
        /// format, size, mip count and byte count. `label` names the source in errors.
        Result<void> validate(const std::string& label) const;
    };

    /// Serialise in the layout above. Deterministic; does not validate (decode does).
    std::vector<std::uint8_t> encodeCrossedQuadsChunk(const CrossedQuadsData& data);

    /// Parse and validate(); never throws, whatever the bytes. Errors name `label`,
    /// "chunk 'crossed-quads' level 0" and the element.
    Result<CrossedQuadsData> decodeCrossedQuadsChunk(const std::vector<std::uint8_t>& bytes, const std::string& label);
}
