#include "TreeLod/ReferenceRenderer.h"

#include "EmbreeScene.h"
#include "TreeLod/AmbientOcclusion.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace TreeLod
{
    namespace
    {
        constexpr int TileSize = 16;

        struct Sample
        {
            bool hit = false;
            glm::vec3 colour{0.0f}; ///< linear, clamped to [0, 1]
            float depth = 0.0f;
            glm::vec3 normal{0.0f};
        };

        /// Everything a pixel needs, fixed for one render() call.
        struct Frame
        {
            const EmbreeScene* scene = nullptr;
            const RenderOptions* options = nullptr;
            glm::dmat4 inverseViewProjection{1.0};
            glm::vec3 eye{0.0f};
            glm::vec3 forward{0.0f, 0.0f, -1.0f};
            glm::vec3 sun{0.0f, 1.0f, 0.0f};
            int grid = 1; ///< n: samples on an n x n grid
            bool valid = false;
        };

        bool isFinite(const glm::dmat4& m)
        {
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r)
                    if (!std::isfinite(m[c][r]))
                        return false;
            return true;
        }

        /// Shade a hit by the LightingSpec contract (see ReferenceRenderer.h).
        Sample shade(const Frame& f, const EmbreeScene::Hit& hit, const glm::vec3& org, const glm::vec3& dir)
        {
            const EmbreeScene& scene = *f.scene;
            const EmbreeScene::Triangle& tri = scene.triangles(hit.part)[hit.prim];
            const Vertex& a = scene.vertex(hit.part, tri.v[0]);
            const Vertex& b = scene.vertex(hit.part, tri.v[1]);
            const Vertex& c = scene.vertex(hit.part, tri.v[2]);
            float w0 = 1.0f - hit.u - hit.v, w1 = hit.u, w2 = hit.v;
            glm::vec3 point = org + dir * hit.t;

            glm::vec3 n = w0 * a.normal + w1 * b.normal + w2 * c.normal;
            float len = glm::length(n);
            if (len > 1e-20f && std::isfinite(len))
                n /= len;
            else if (tri.faceNormal != glm::vec3(0.0f))
                n = tri.faceNormal;
            else
                n = -glm::normalize(dir); // never hit in practice: degenerate triangles are skipped
            // The side seen. Leaves: from the shading normal and the vector to the camera
            // position, as the GLSL does. Bark: from the winding (only double-sided bark is
            // ever hit from behind, the rest is culled).
            bool back = hit.part == EmbreeScene::Leaves ? glm::dot(n, f.eye - point) < 0.0f
                                                        : glm::dot(tri.faceNormal, dir) > 0.0f;
            if (back)
                n = -n;

            const Material& m = scene.materials()[tri.material];
            glm::vec3 tint(m.baseColour);
            if (hit.part == EmbreeScene::Leaves && back && m.backColour != glm::vec3(0.0f))
                tint = m.backColour;
            glm::vec3 texel(1.0f);
            if (const LinearTexture* tex = scene.texture(m))
                texel = glm::vec3(tex->sample(w0 * a.uv + w1 * b.uv + w2 * c.uv));
            glm::vec3 albedo = tint * texel;

            float ao = 1.0f;
            if (const AmbientOcclusion* occlusion = f.options->ambientOcclusion)
            {
                const std::vector<float>& values =
                    hit.part == EmbreeScene::Bark ? occlusion->barkVertex : occlusion->leafVertex;
                ao = w0 * values[tri.v[0]] + w1 * values[tri.v[1]] + w2 * values[tri.v[2]];
            }

            const LightingSpec& light = f.options->lighting;
            glm::vec3 colour =
                albedo * (light.ambientColour * ao + light.sunColour * std::max(0.0f, glm::dot(n, f.sun)));
            Sample s;
            s.hit = true;
            s.colour = glm::clamp(colour, glm::vec3(0.0f), glm::vec3(1.0f));
            s.depth = glm::dot(point - f.eye, f.forward);
            s.normal = n;
            return s;
        }

        /// Trace the camera ray through pixel-space position (x, y) (0,0 = top-left corner).
        Sample traceSample(const Frame& f, double x, double y)
        {
            const RenderOptions& o = *f.options;
            double ndcX = 2.0 * x / o.width - 1.0, ndcY = 1.0 - 2.0 * y / o.height;
            glm::dvec4 nearH = f.inverseViewProjection * glm::dvec4(ndcX, ndcY, -1.0, 1.0);
            glm::dvec4 farH = f.inverseViewProjection * glm::dvec4(ndcX, ndcY, 1.0, 1.0);
            glm::dvec3 nearP = glm::dvec3(nearH) / nearH.w, farP = glm::dvec3(farH) / farH.w;
            glm::dvec3 span = farP - nearP;
            double length = glm::length(span);
            if (!(length > 0.0) || !std::isfinite(length))
                return Sample{};
            glm::vec3 org(nearP), dir(span / length);
            EmbreeScene::Hit hit = f.scene->intersect(org, dir, 0.0f, float(length));
            if (!hit.valid)
                return Sample{};
            return shade(f, hit, org, dir);
        }
    }

    ReferenceRenderer::ReferenceRenderer(const TreeModel& model) : mScene(std::make_unique<EmbreeScene>(model)) {}

    ReferenceRenderer::~ReferenceRenderer() = default;

    RenderImages ReferenceRenderer::render(const CameraSpec& camera, const RenderOptions& options) const
    {
        int grid = int(std::lround(std::sqrt(double(std::max(options.samplesPerPixel, 0)))));
        if (grid < 1 || grid > 16 || grid * grid != options.samplesPerPixel)
            throw std::invalid_argument("ReferenceRenderer: samplesPerPixel " + std::to_string(options.samplesPerPixel) +
                                        " is not n*n with n in 1..16");
        const TreeModel& model = mScene->model();
        if (const AmbientOcclusion* ao = options.ambientOcclusion)
            if (ao->barkVertex.size() != model.barkVertices.size() ||
                ao->leafVertex.size() != model.leafVertices.size())
                throw std::invalid_argument("ReferenceRenderer: ambient occlusion has " +
                                            std::to_string(ao->barkVertex.size()) + " bark and " +
                                            std::to_string(ao->leafVertex.size()) + " leaf values for " +
                                            std::to_string(model.barkVertices.size()) + " and " +
                                            std::to_string(model.leafVertices.size()) + " vertices");

        RenderImages out;
        out.width = std::max(options.width, 0);
        out.height = std::max(options.height, 0);
        if (out.width == 0 || out.height == 0)
            return out;
        std::size_t count = std::size_t(out.width) * out.height;
        const LightingSpec& light = options.lighting;
        glm::vec3 backgroundLinear(srgbToLinear(light.background.r), srgbToLinear(light.background.g),
                                   srgbToLinear(light.background.b));
        out.colour = Image(out.width, out.height,
                           options.transparentBackground ? glm::vec4(0.0f) : glm::vec4(light.background, 1.0f));
        out.alpha.assign(count, 0.0f);
        out.depth.assign(count, std::numeric_limits<float>::infinity());
        out.normal.assign(count, glm::vec3(0.0f));

        Frame f;
        f.scene = mScene.get();
        f.options = &options;
        f.grid = grid;
        f.eye = camera.position;
        f.forward = glm::normalize(camera.target - camera.position);
        float sunLength = glm::length(light.sunDirection);
        f.sun = sunLength > 0.0f ? light.sunDirection / sunLength : glm::vec3(0.0f);
        glm::dmat4 viewProjection = glm::dmat4(camera.projectionMatrix(float(out.width) / float(out.height))) *
                                    glm::dmat4(camera.viewMatrix());
        f.inverseViewProjection = glm::inverse(viewProjection);
        if (!isFinite(f.inverseViewProjection) || !std::isfinite(f.forward.x))
            return out; // degenerate camera: background only

        // Samples in row-major order; the one used for depth/normal is the hitting sample
        // nearest the pixel centre (ties: first in this order).
        std::vector<glm::dvec2> offsets;
        std::vector<double> centreDistance;
        for (int sy = 0; sy < grid; ++sy)
            for (int sx = 0; sx < grid; ++sx)
            {
                glm::dvec2 o((sx + 0.5) / grid, (sy + 0.5) / grid);
                offsets.push_back(o);
                centreDistance.push_back(glm::length(o - glm::dvec2(0.5)));
            }
        std::vector<int> byDistance(offsets.size());
        for (std::size_t i = 0; i < byDistance.size(); ++i)
            byDistance[i] = int(i);
        std::stable_sort(byDistance.begin(), byDistance.end(),
                         [&](int a, int b) { return centreDistance[a] < centreDistance[b]; });

        int tilesX = (out.width + TileSize - 1) / TileSize, tilesY = (out.height + TileSize - 1) / TileSize;
        float invSamples = 1.0f / float(offsets.size());
        tbb::parallel_for(tbb::blocked_range<int>(0, tilesX * tilesY), [&](const tbb::blocked_range<int>& range) {
            std::vector<Sample> samples(offsets.size());
            for (int tile = range.begin(); tile != range.end(); ++tile)
            {
                int x0 = (tile % tilesX) * TileSize, y0 = (tile / tilesX) * TileSize;
                int x1 = std::min(x0 + TileSize, out.width), y1 = std::min(y0 + TileSize, out.height);
                for (int y = y0; y < y1; ++y)
                    for (int x = x0; x < x1; ++x)
                    {
                        int hits = 0;
                        glm::vec3 sum(0.0f);
                        for (std::size_t s = 0; s < offsets.size(); ++s)
                        {
                            samples[s] = traceSample(f, x + offsets[s].x, y + offsets[s].y);
                            if (samples[s].hit)
                            {
                                ++hits;
                                sum += samples[s].colour;
                            }
                        }
                        if (hits == 0)
                            continue;
                        std::size_t p = std::size_t(y) * out.width + x;
                        float coverage = float(hits) * invSamples;
                        glm::vec3 linear = options.transparentBackground
                                               ? sum / float(hits)
                                               : (sum + backgroundLinear * float(int(offsets.size()) - hits)) * invSamples;
                        out.colour.pixels[p] =
                            glm::vec4(linearToSrgb(linear.r), linearToSrgb(linear.g), linearToSrgb(linear.b),
                                      options.transparentBackground ? coverage : 1.0f);
                        out.alpha[p] = coverage;
                        for (int s : byDistance)
                            if (samples[s].hit)
                            {
                                out.depth[p] = samples[s].depth;
                                out.normal[p] = samples[s].normal;
                                break;
                            }
                    }
            }
        });
        return out;
    }

    CameraSpec sideViewCamera(const glm::vec3& middle, const glm::vec3& towards, float nearDepth, float farDepth,
                              float height, float pad)
    {
        CameraSpec camera;
        camera.orthographic = true;
        camera.position = middle + (farDepth + pad) * towards;
        camera.target = middle + (nearDepth - pad) * towards;
        camera.up = glm::vec3(0.0f, 1.0f, 0.0f);
        camera.orthoHeight = height;
        camera.nearClip = 0.5f * pad;
        camera.farClip = (farDepth - nearDepth) + 1.5f * pad;
        return camera;
    }

    RenderOptions albedoRenderOptions(int width, int height, int samplesPerPixel)
    {
        RenderOptions render;
        render.width = width;
        render.height = height;
        render.samplesPerPixel = samplesPerPixel;
        render.lighting.sunColour = glm::vec3(0.0f);
        render.lighting.ambientColour = glm::vec3(1.0f);
        render.transparentBackground = true;
        return render;
    }
}
