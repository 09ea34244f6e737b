// EmbreeScene (private to TreeLodBake): one Embree scene of a TreeModel's bark and leaves with
// the alpha test and back-face rules of ReferenceRenderer.h, shared by the reference renderer
// and the ambient occlusion caster.
#pragma once

#include "TreeLod/TreeModel.h"

#include <embree3/rtcore.h>
#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace TreeLod
{
    /// A texture decoded to linear RGB (sRGB decoded) with straight alpha, for bilinear lookups.
    struct LinearTexture
    {
        int width = 0;
        int height = 0;
        std::vector<glm::vec4> texels; ///< width * height, rows top to bottom
        std::vector<std::uint8_t> alpha; ///< the alpha channel alone, compact for the alpha test

        /// Bilinear lookup of the four nearest texels, REPEAT wrapping, UV (0,0) = top-left
        /// corner; non-finite UVs read as 0.
        glm::vec4 sample(glm::vec2 uv) const;
        /// The same lookup of the alpha channel only (equal to sample(uv).a up to rounding).
        float sampleAlpha(glm::vec2 uv) const;
    };

    class EmbreeScene
    {
    public:
        /// Also the Embree geometry ID of that part.
        enum Part : std::uint8_t
        {
            Bark = 0,
            Leaves = 1
        };

        /// One triangle as Embree sees it (primID indexes these, per part).
        struct Triangle
        {
            std::uint32_t v[3];    ///< into barkVertices or leafVertices
            std::uint32_t material; ///< into materials(); always valid
            glm::vec3 faceNormal;  ///< unit cross(p1 - p0, p2 - p0), 0 when degenerate
        };

        struct Hit
        {
            bool valid = false;
            Part part = Bark;
            std::uint32_t prim = 0;
            float u = 0.0f, v = 0.0f; ///< Embree barycentrics: p = (1-u-v) p0 + u p1 + v p2
            float t = 0.0f;
        };

        /// Throws std::runtime_error when Embree fails. `model` must outlive the scene.
        explicit EmbreeScene(const TreeModel& model);
        ~EmbreeScene();
        EmbreeScene(const EmbreeScene&) = delete;
        EmbreeScene& operator=(const EmbreeScene&) = delete;

        /// Closest hit seen by a camera ray: single-sided bark is culled from behind, leaves
        /// are alpha-tested. `dir` need not be unit; t is in units of |dir|. Rays with
        /// non-finite or huge (> 1e18) components miss.
        Hit intersect(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar) const;

        /// Whether anything blocks the segment (bark from both sides, alpha-tested leaves);
        /// false for rays intersect() would not trace.
        bool occluded(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar) const;

        const TreeModel& model() const { return mModel; }
        const std::vector<Triangle>& triangles(Part part) const { return mTriangles[part]; }
        const Vertex& vertex(Part part, std::uint32_t index) const
        {
            return part == Bark ? mModel.barkVertices[index] : mModel.leafVertices[index];
        }
        /// The model's materials plus a white default (last) for out-of-range references.
        const std::vector<Material>& materials() const { return mMaterials; }
        /// nullptr when the material has no (valid) texture.
        const LinearTexture* texture(const Material& material) const;
        /// Length of the bounding-box diagonal of the model's vertices (0 when empty).
        float diagonal() const { return mDiagonal; }

        /// baseColour.a * texture alpha at the hit, the value the alpha test compares.
        float leafAlpha(std::uint32_t prim, float u, float v) const;

    private:
        /// What the alpha test of one leaf triangle reads, in one place (the filter is hot).
        struct AlphaTest
        {
            glm::vec2 uv[3];
            const LinearTexture* texture; ///< nullptr: texture alpha 1
            float baseAlpha;
            float cutoff;
        };

        static void leafFilter(const RTCFilterFunctionNArguments* args);
        static void barkCullFilter(const RTCFilterFunctionNArguments* args);
        void addGeometry(Part part, const std::vector<Vertex>& vertices);

        const TreeModel& mModel;
        std::vector<Material> mMaterials;
        std::vector<LinearTexture> mTextures;
        std::vector<Triangle> mTriangles[2];
        std::vector<AlphaTest> mAlphaTests; ///< per leaf triangle
        std::vector<bool> mSingleSided; ///< per material: culled from behind (bark only)
        float mDiagonal = 0.0f;
        RTCDevice mDevice = nullptr;
        RTCScene mScene = nullptr;
    };
}
