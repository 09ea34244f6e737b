// ImpostorViews: what the impostor bakers share (ImpostorBaker.h, OctahedralImpostorBaker.h):
// one orthographic view of a tree rendered by the CPU ReferenceRenderer into the texels of an
// impostor texture, and the mip chain of the normal texture.
//
// Per texel of a view: linear albedo, the shading normal's x and y on the view's right and up
// axes (z towards the viewer, reconstructed by the shader), ambient occlusion and a fourth
// value (the octahedral impostor's depth; 1 for the quad). Uncovered texels are bled from
// their covered neighbours, so filtering never pulls in an unrelated value.
#pragma once

#include "TreeLod/Image.h"
#include "TreeLod/ModelChunk.h"
#include "TreeLod/ReferenceRenderer.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace TreeLod
{
    struct ImpostorView
    {
        int width = 0, height = 0;
        std::vector<glm::vec3> albedo;   ///< linear
        std::vector<glm::vec4> normalAo; ///< normal x, y (view frame), AO, the fourth value
        std::vector<float> coverage;     ///< in [0, 1]
    };

    /// The texels of one view from its albedo render `plain` and, with AO, the same view rendered
    /// with ambient occlusion (`occluded`, null without AO: AO = 1). `right`, `up`: the view's
    /// axes in the model's space. `fourth(i)` gives the fourth value of covered texel i.
    template <typename Fourth>
    ImpostorView impostorView(const RenderImages& plain, const RenderImages* occluded, const glm::vec3& right,
                              const glm::vec3& up, Fourth fourth);

    /// Bleed every value of `view` into its uncovered texels (bleedValues, `rings` rings; where
    /// nothing is covered: albedo 0.2, a normal facing the viewer, AO 1, `fourthFallback`).
    void bleedImpostorView(ImpostorView& view, int rings, float fourthFallback);

    /// The normal texture of the impostor bakers (RGBA8, `mipCount` levels, 0 = all): level 0
    /// from `normalAo` (R, G = x, y * 0.5 + 0.5, B = AO, A = the fourth value), each further level
    /// the coverage-weighted mean of its children (the plain mean where none is covered), the
    /// normal renormalised.
    GpuTexture impostorNormalTexture(const std::string& name, std::uint32_t width, std::uint32_t height,
                                     std::vector<glm::vec4> normalAo, std::vector<float> coverage,
                                     std::uint32_t mipCount = 0);

    // ---- implementation ------------------------------------------------------------------

    template <typename Fourth>
    ImpostorView impostorView(const RenderImages& plain, const RenderImages* occluded, const glm::vec3& right,
                              const glm::vec3& up, Fourth fourth)
    {
        ImpostorView view;
        view.width = plain.width;
        view.height = plain.height;
        const std::size_t count = std::size_t(plain.width) * std::size_t(plain.height);
        view.albedo.assign(count, glm::vec3(0.0f));
        view.normalAo.assign(count, glm::vec4(0.0f, 0.0f, 1.0f, 1.0f));
        view.coverage = plain.alpha;
        for (std::size_t i = 0; i < count; ++i)
        {
            if (!(plain.alpha[i] > 0.0f))
                continue;
            const glm::vec4& c = plain.colour.pixels[i];
            view.albedo[i] = glm::vec3(srgbToLinear(c.r), srgbToLinear(c.g), srgbToLinear(c.b));
            float ao = 1.0f;
            if (occluded)
            {
                const glm::vec4& d = occluded->colour.pixels[i];
                const float withAo = srgbToLinear(d.r) + srgbToLinear(d.g) + srgbToLinear(d.b);
                const float without = view.albedo[i].r + view.albedo[i].g + view.albedo[i].b;
                ao = without > 1e-6f ? glm::clamp(withAo / without, 0.0f, 1.0f) : 1.0f;
            }
            const glm::vec3& n = plain.normal[i];
            view.normalAo[i] = glm::vec4(glm::dot(n, right), glm::dot(n, up), ao, fourth(i));
        }
        return view;
    }
}
