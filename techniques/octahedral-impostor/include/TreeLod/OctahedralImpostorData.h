// OctahedralImpostorData: the octahedral impostor, package chunk "octahedral-impostor": the tree
// baked from many directions over the upper hemisphere into one atlas of frames, drawn as one
// camera-facing quad that blends the three frames nearest the view (as game engines draw far
// trees; the hemi-octahedral layout of Brucks, "Octahedral Impostors", 2018, after Praun and
// Hoppe's octahedral parametrisation, 2003). The baker is OctahedralImpostorBaker.h, the GPU
// side OctahedralImpostorResources.h and materials/TreeLodOctahedralImpostor.*.
//
// ---- Views --------------------------------------------------------------------------------
// framesPerSide N frames a side, frame (i, j) in column i, row j (rows top to bottom) seen from
// the unit direction octahedralFrameDirection(i, j, N) (towards the viewer, y >= 0): the hemi-
// octahedral decoding of the grid point (2i / (N - 1) - 1, 2j / (N - 1) - 1), so the outer ring
// of frames lies on the horizon and the centre looks down. A view direction d picks the grid
// cell around hemiOctahedralEncode(d) (below the horizon: d's horizontal part) and blends the
// three frames of the triangle it falls in, barycentric weights.
//
// ---- A frame --------------------------------------------------------------------------------
// Orthographic along -towards with the axes of octahedralFrameAxes: right = cross(+Y, towards)
// normalised (+X when towards is +Y), up = cross(towards, right). The frame is a square of side
// octahedralFrameSide(towards) metres centred on the tree's centre C = (0, (bottom + top) / 2, 0)
// (the trunk axis is the local y axis): the projection of the tree's bounding cylinder (radius,
// bottom, top) plus IMPOSTOR_MARGIN_TEXELS empty texels each side. Texel (x, y) of a frame covers
// C + right * (u - 0.5) * side + up * (0.5 - v) * side, u = (x + 0.5) / F, v = (y + 0.5) / F
// with F = frame texels a side.
//
// ---- Textures (frames F x F texels, atlas N F x N F) -------------------------------------
// colour: RGB = sRGB albedo, A = coverage (as ImpostorData.h: bled, coverage-preserving mips).
// normal: R, G = x, y of the shading normal on the frame's right and up axes (n * 0.5 + 0.5; z
//   towards the viewer, reconstructed), B = ambient occlusion, A = depth: the first surface's
//   distance in front of the frame's plane through C, along towards, as 0.5 + 0.5 d / R with R
//   the cylinder's circumscribed radius (octahedralDepthRadius); 0.5 where uncovered (bled).
// Mips: mipCount levels of box filtering aligned to the frames (F a multiple of 2^(mipCount-1)),
// the last level's frames at least 4 texels, so no level mixes two frames.
//
// ---- Chunk layout, formatVersion 1 (OCTAHEDRAL_IMPOSTOR_CHUNK_FORMAT_VERSION) --------------
// Little-endian, GpuTexture as in ModelChunk.h:
//   u32 flags (0; others are an error), u32 framesPerSide N in [2, 32],
//   f32 radius, f32 bottom, f32 top, f32 alphaCutoff
//   GpuTexture colour   RGBA8 or DXT5, square N F, F a multiple of 4, >= 8
//   GpuTexture normal   RGBA8 or DXT5 (depth needs alpha), the colour's size and mip count
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
    constexpr const char* OCTAHEDRAL_IMPOSTOR_CHUNK = "octahedral-impostor";
    constexpr std::uint32_t OCTAHEDRAL_IMPOSTOR_CHUNK_FORMAT_VERSION = 1;
    /// Empty texels around the tree on each side of a frame (as the quad impostor's).
    constexpr std::uint32_t OCTAHEDRAL_MARGIN_TEXELS = 2;

    struct OctahedralImpostorData
    {
        std::uint32_t framesPerSide = 0; ///< N in [2, 32]
        float radius = 0.0f;             ///< metres, > 0: the bounding cylinder about the local y axis
        float bottom = 0.0f, top = 0.0f; ///< metres, top > bottom
        float alphaCutoff = 0.5f;        ///< in (0, 1]
        GpuTexture colour;
        GpuTexture normal;

        /// Texels a side of one frame at level 0.
        std::uint32_t frameTexels() const { return framesPerSide ? colour.width / framesPerSide : 0; }
        /// Bytes on the GPU: both textures as stored, all mips.
        std::uint64_t gpuBytes() const { return colour.data.size() + normal.data.size(); }

        /// Finite cylinder, cutoff, frame count, texture formats, square atlas of whole frames,
        /// mips aligned to the frames, both textures alike. `label` names the source in errors.
        Result<void> validate(const std::string& label) const;
    };

    /// Hemi-octahedral encoding of a unit direction with y >= 0 (a lower one is first flattened to
    /// its horizontal part) to [-1, 1]^2; the horizon is the square's edge, +Y its centre.
    glm::vec2 hemiOctahedralEncode(const glm::vec3& direction);
    /// The inverse of hemiOctahedralEncode for a point of [-1, 1]^2: a unit direction, y >= 0.
    glm::vec3 hemiOctahedralDecode(const glm::vec2& point);
    /// Frame (i, j)'s view direction (towards the viewer), N = framesPerSide >= 2.
    glm::vec3 octahedralFrameDirection(std::uint32_t i, std::uint32_t j, std::uint32_t framesPerSide);

    struct OctahedralFrameAxes
    {
        glm::vec3 right, up;
    };
    /// The frame axes of a view from `towards` (unit).
    OctahedralFrameAxes octahedralFrameAxes(const glm::vec3& towards);
    /// Half the extent, along the up axis of a view from `towards`, of the bounding cylinder.
    float octahedralHalfHeight(const glm::vec3& towards, float radius, float bottom, float top);
    /// Side of the square frame seen from `towards` (metres), margins included, F texels a side.
    float octahedralFrameSide(const glm::vec3& towards, float radius, float bottom, float top,
                              std::uint32_t frameTexels);
    /// The radius that normalises depth: the bounding cylinder's circumscribed sphere's.
    float octahedralDepthRadius(float radius, float bottom, float top);

    /// Serialise in the layout above. Deterministic; does not validate (decode does).
    std::vector<std::uint8_t> encodeOctahedralImpostorChunk(const OctahedralImpostorData& data);

    /// Parse and validate(); errors name `label`, "chunk 'octahedral-impostor' level 0" and the
    /// element.
    Result<OctahedralImpostorData> decodeOctahedralImpostorChunk(const std::vector<std::uint8_t>& bytes,
                                                                 const std::string& label);
}
