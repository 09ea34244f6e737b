// ReferenceRenderer: the CPU ray-traced reference image of a TreeModel (Embree + TBB).
// Bakers measure their image error against it; the GLSL materials implement the same shading.
//
// Camera: rays are built from inverse(projection * view) of the CameraSpec (OpenGL clip
// conventions), from the near plane (NDC z = -1) to the far plane (NDC z = +1), so a
// rasteriser drawing the same camera and size lines up pixel for pixel. Pixel (0, 0) is the
// TOP-left pixel, rows run top to bottom (PNG order); a pixel's samples lie on an n x n grid
// at the centres of its sub-cells (n * n = samplesPerPixel; n = 1 samples the pixel centre,
// as rasterisation does). No randomness.
//
// Visibility: the closest hit along the ray within [near, far].
//   - Bark is opaque. Bark triangles whose material is not doubleSided are invisible from
//     their back (back-face culling, as the GPU draws them); doubleSided bark is seen from
//     both sides.
//   - Leaves are always two-sided and alpha-tested: a hit is discarded (the ray goes on) where
//     baseColour.a * textureAlpha(uv) < alphaCutoff. textureAlpha is the bilinear interpolation
//     of the four nearest texels of the full-resolution texture (texel centres at
//     ((i + 0.5) / w, (j + 0.5) / h), UV (0, 0) = top-left texel corner as in glTF, REPEAT
//     wrapping), no mip-mapping. Without a texture textureAlpha = 1.
//   - Bark's back side (for culling and for double-sided bark's shading) is where its
//     geometric normal cross(p1 - p0, p2 - p0) (counter-clockwise front, as OpenGL) faces
//     away from the camera.
//
// Shading (the LightingSpec contract, all in linear space):
//   n0     = barycentric interpolation of the vertex normals, normalised (the unit geometric
//            normal where that is zero or not finite).
//   side   = leaves: back where dot(n0, cameraPosition - hitPoint) < 0 (the shading normal
//            turned away from the camera position; like the GLSL, which cannot trust
//            gl_FrontFacing under render-to-texture); bark: back where the winding faces away
//            (only double-sided bark is seen from there).
//   n      = n0 on the front, -n0 on the back, so a leaf's n always faces the camera.
//   albedo = baseColour.rgb * srgbToLinear(texture.rgb(uv))    (same bilinear lookup as alpha;
//            texture = white without one). On the back side of a leaf whose material has a
//            nonzero backColour, backColour replaces baseColour.rgb:
//            albedo = backColour * srgbToLinear(texture.rgb(uv)).
//   ao     = barycentric interpolation of RenderOptions::ambientOcclusion's vertex values,
//            1 without it.
//   colour = albedo * (ambientColour * ao + sunColour * max(0, dot(n, sunDirection))),
//            sunDirection normalised, colour clamped to [0, 1] per sample (as a UNORM render
//            target does).
// A sample that hits nothing has the colour srgbToLinear(background) (opaque background), or
// is transparent with RenderOptions::transparentBackground.
//
// Supersampling: colour = mean of the samples' linear colours, then linearToSrgb;
// alpha = fraction of samples that hit. depth and normal come from one sample: the hitting
// sample nearest the pixel centre (ties: first in row-major sample order), so they are set
// wherever alpha > 0.
//
// Deterministic and thread-safe: each pixel is computed on its own (tbb::parallel_for over
// tiles), so the images are byte-identical for any thread count.
#pragma once

#include "TreeLod/Camera.h"
#include "TreeLod/Image.h"
#include "TreeLod/TreeModel.h"

#include <glm/glm.hpp>

#include <memory>
#include <vector>

namespace TreeLod
{
    struct AmbientOcclusion;
    class EmbreeScene;

    struct RenderOptions
    {
        int width = 512;   ///< pixels, >= 0 (0 gives empty images)
        int height = 512;
        int samplesPerPixel = 4; ///< n * n for n = 1..16: 1, 4 (2x2), 9, 16 ... stratified
        LightingSpec lighting;
        /// Optional per-vertex AO that darkens the ambient term; when set, its sizes must
        /// equal the model's barkVertices and leafVertices counts (else std::invalid_argument).
        const AmbientOcclusion* ambientOcclusion = nullptr;
        /// false: colour is opaque, the background is lighting.background.
        /// true: colour.rgb is the mean of the hitting samples only (straight alpha, 0 where
        /// nothing is hit) and colour.a = coverage, e.g. for billboard and impostor textures.
        bool transparentBackground = false;
    };

    struct RenderImages
    {
        Image colour;              ///< sRGB; alpha 1 (or coverage with transparentBackground)
        std::vector<float> alpha;  ///< coverage in [0, 1] per pixel: fraction of samples that hit
        std::vector<float> depth;  ///< metres along the camera's view axis (view-space -z) from
                                   ///< the camera position; +inf where alpha = 0
        std::vector<glm::vec3> normal; ///< world-space unit shading normal n (see above); it faces
                                       ///< the camera (always for leaves; for bark except where
                                       ///< interpolated normals turn away near silhouettes);
                                       ///< 0 where alpha = 0
        int width = 0;
        int height = 0;
    };

    /// The orthographic side view that impostor-like bakers render a tree with: looking along
    /// -`towards` (unit, horizontal) at the box whose extent along `towards` is [nearDepth,
    /// farDepth] (farDepth nearest the camera), through `middle` (on the view axis, depth 0),
    /// `height` metres tall, with `pad` metres of clearance in front and behind.
    CameraSpec sideViewCamera(const glm::vec3& middle, const glm::vec3& towards, float nearDepth, float farDepth,
                              float height, float pad);
    /// Render options whose colour is albedo: white ambient light, no sun, a transparent
    /// background (colour.a = coverage), `width` x `height`, `samplesPerPixel` samples.
    RenderOptions albedoRenderOptions(int width, int height, int samplesPerPixel);

    /// Renders one TreeModel; build once, render many views.
    class ReferenceRenderer
    {
    public:
        /// Builds the Embree scene (bark + leaves) and linear copies of the textures.
        /// `model` must outlive the renderer and not change meanwhile. Triangles with
        /// out-of-range indices are skipped; degenerate triangles and triangles with non-finite
        /// or huge (> 1.8e18) coordinates are never hit.
        /// Throws std::runtime_error if Embree cannot be initialised.
        explicit ReferenceRenderer(const TreeModel& model);
        ~ReferenceRenderer();
        ReferenceRenderer(const ReferenceRenderer&) = delete;
        ReferenceRenderer& operator=(const ReferenceRenderer&) = delete;

        /// Thread-safe and deterministic. Throws std::invalid_argument when samplesPerPixel is
        /// not a square in [1, 256] or the AO sizes do not match the model.
        RenderImages render(const CameraSpec& camera, const RenderOptions& options) const;

    private:
        std::unique_ptr<EmbreeScene> mScene;
    };
}
