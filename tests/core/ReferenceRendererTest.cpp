// ReferenceRenderer and AmbientOcclusion on tiny hand-made TreeModels.
//
// Most tests look at a quad in the plane z = 0 through an orthographic camera on the +Z axis
// that shows [-2, 2] x [-2, 2] metres on 40 x 40 pixels: 10 pixels per metre, pixel column px
// covers x in [-2 + px/10, -2 + (px+1)/10], row py covers y in [2 - (py+1)/10, 2 - py/10].
#include "TreeLod/AmbientOcclusion.h"
#include "TreeLod/Image.h"
#include "TreeLod/ReferenceRenderer.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>

using namespace TreeLod;

namespace
{
    // ---- model building -------------------------------------------------------------------

    Material barkMaterial(glm::vec3 colour, bool doubleSided = false)
    {
        Material m;
        m.name = "bark";
        m.baseColour = glm::vec4(colour, 1.0f);
        m.doubleSided = doubleSided;
        return m;
    }

    Material leafMaterial(glm::vec3 colour, glm::vec3 back, std::int32_t texture)
    {
        Material m;
        m.name = "leaf";
        m.baseColour = glm::vec4(colour, 1.0f);
        m.backColour = back;
        m.texture = texture;
        m.isLeaf = true;
        m.doubleSided = true;
        return m;
    }

    /// Quad corner, corner + u, corner + u + v, corner + v; front (counter-clockwise) faces
    /// cross(u, v). UV (0,0) is the corner + v end (top-left when v points up), as in glTF.
    void quadVertices(std::vector<Vertex>& out, glm::vec3 corner, glm::vec3 u, glm::vec3 v)
    {
        glm::vec3 n = glm::normalize(glm::cross(u, v));
        out.push_back({corner, n, {0.0f, 1.0f}});
        out.push_back({corner + u, n, {1.0f, 1.0f}});
        out.push_back({corner + u + v, n, {1.0f, 0.0f}});
        out.push_back({corner + v, n, {0.0f, 0.0f}});
    }

    void addBarkQuad(TreeModel& m, glm::vec3 corner, glm::vec3 u, glm::vec3 v, std::uint32_t material)
    {
        std::uint32_t base = std::uint32_t(m.barkVertices.size());
        quadVertices(m.barkVertices, corner, u, v);
        for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u})
            m.barkIndices.push_back(base + i);
        m.barkTriangleMaterial.push_back(material);
        m.barkTriangleMaterial.push_back(material);
    }

    void addLeafQuad(TreeModel& m, glm::vec3 corner, glm::vec3 u, glm::vec3 v, std::uint32_t material)
    {
        Leaf leaf;
        leaf.firstVertex = std::uint32_t(m.leafVertices.size());
        leaf.vertexCount = 4;
        leaf.firstIndex = std::uint32_t(m.leafIndices.size());
        leaf.indexCount = 6;
        leaf.material = material;
        quadVertices(m.leafVertices, corner, u, v);
        for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u})
            m.leafIndices.push_back(leaf.firstVertex + i);
        m.leaves.push_back(leaf);
        m.updateLeafRecord(m.leaves.size() - 1);
    }

    TextureImage halfTransparentTexture()
    {
        // 8 x 2 texels: columns 0-3 transparent, 4-7 opaque white.
        TextureImage t;
        t.name = "half";
        t.width = 8;
        t.height = 2;
        for (int y = 0; y < t.height; ++y)
            for (int x = 0; x < t.width; ++x)
                for (int c = 0; c < 4; ++c)
                    t.rgba.push_back(c < 3 ? 255 : (x < 4 ? 0 : 255));
        return t;
    }

    /// splitmix64: a portable deterministic random stream for synthetic trees.
    struct Random
    {
        std::uint64_t state;
        explicit Random(std::uint64_t seed) : state(seed) {}
        float next()
        {
            std::uint64_t x = (state += 0x9E3779B97F4A7C15ull);
            x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
            x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
            return float((x ^ (x >> 31)) >> 40) / 16777216.0f;
        }
        float range(float lo, float hi) { return lo + (hi - lo) * next(); }
        /// A point of [-1, 1]^3, drawn z, y, x (named: the order of a call's arguments is unspecified).
        glm::vec3 inCube()
        {
            const float z = range(-1.0f, 1.0f);
            const float y = range(-1.0f, 1.0f);
            return glm::vec3(range(-1.0f, 1.0f), y, z);
        }
    };

    /// A small tree about 5.8 * scale metres tall: a tapered trunk cylinder and `leafCount`
    /// textured leaf quads in an ellipsoidal crown.
    TreeModel syntheticTree(int leafCount, float scale, float leafSize)
    {
        TreeModel m;
        m.name = "synthetic";
        m.materials.push_back(barkMaterial({0.30f, 0.20f, 0.12f}));
        m.materials.push_back(leafMaterial({1.0f, 1.0f, 1.0f}, {0.75f, 0.9f, 0.45f}, 0));
        TextureImage tex;
        tex.name = "leaf";
        tex.width = tex.height = 32;
        for (int y = 0; y < 32; ++y)
            for (int x = 0; x < 32; ++x)
            {
                float u = (x + 0.5f) / 32.0f - 0.5f, v = (y + 0.5f) / 32.0f - 0.5f;
                bool inside = (u / 0.48f) * (u / 0.48f) + (v / 0.3f) * (v / 0.3f) < 1.0f;
                bool rib = std::abs(v) < 0.03f;
                tex.rgba.insert(tex.rgba.end(), {std::uint8_t(rib ? 120 : 70), std::uint8_t(rib ? 170 : 130),
                                                 std::uint8_t(rib ? 70 : 40), std::uint8_t(inside ? 255 : 0)});
            }
        m.textures.push_back(tex);

        const int sides = 12, rings = 6;
        for (int r = 0; r <= rings; ++r)
            for (int s = 0; s <= sides; ++s)
            {
                float h = 3.5f * r / rings, radius = 0.25f - 0.13f * r / rings;
                float a = 2.0f * 3.14159265f * s / sides;
                glm::vec3 n(std::cos(a), 0.0f, -std::sin(a));
                m.barkVertices.push_back({scale * (glm::vec3(0.0f, h, 0.0f) + radius * n), n,
                                          {float(s) / sides, float(r) / rings}});
            }
        for (int r = 0; r < rings; ++r)
            for (int s = 0; s < sides; ++s)
            {
                std::uint32_t a = r * (sides + 1) + s, b = a + 1, c = a + sides + 1, d = c + 1;
                for (std::uint32_t i : {a, b, d, a, d, c})
                    m.barkIndices.push_back(i);
                m.barkTriangleMaterial.insert(m.barkTriangleMaterial.end(), {0u, 0u});
            }

        Random rng(7);
        for (int i = 0; i < leafCount; ++i)
        {
            glm::vec3 p;
            do
                p = rng.inCube();
            while (glm::dot(p, p) > 1.0f);
            glm::vec3 centre = glm::vec3(0.0f, 4.2f, 0.0f) + p * glm::vec3(2.0f, 1.6f, 2.0f);
            glm::vec3 n;
            do
                n = rng.inCube();
            while (glm::dot(n, n) > 1.0f || glm::dot(n, n) < 1e-3f);
            n = glm::normalize(n);
            glm::vec3 t = glm::normalize(glm::cross(n, std::abs(n.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0)));
            glm::vec3 b = glm::cross(n, t);
            glm::vec3 u = t * leafSize, v = b * leafSize;
            addLeafQuad(m, scale * (centre - 0.5f * (u + v)), scale * u, scale * v, 1);
        }
        m.updateBounds();
        return m;
    }

    // ---- cameras and checks -----------------------------------------------------------------

    CameraSpec frontOrtho(float z = 5.0f)
    {
        CameraSpec c;
        c.position = {0.0f, 0.0f, z};
        c.target = {0.0f, 0.0f, 0.0f};
        c.orthographic = true;
        c.orthoHeight = 4.0f;
        c.nearClip = 0.1f;
        c.farClip = 100.0f;
        return c;
    }

    RenderOptions smallOptions(int samples = 1)
    {
        RenderOptions o;
        o.width = o.height = 40;
        o.samplesPerPixel = samples;
        o.lighting.sunDirection = glm::normalize(glm::vec3(0.0f, 0.6f, 0.8f));
        o.lighting.sunColour = {1.0f, 0.5f, 0.25f};
        o.lighting.ambientColour = {0.2f, 0.2f, 0.2f};
        o.lighting.background = {0.1f, 0.2f, 0.3f};
        return o;
    }

    float srgb(float linear) // IEC 61966-2-1, written out independently of Image.cpp
    {
        return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
    }

    float linear(float srgbValue)
    {
        return srgbValue <= 0.04045f ? srgbValue / 12.92f : std::pow((srgbValue + 0.055f) / 1.055f, 2.4f);
    }

    /// Pixels with alpha > 0 must be exactly the rectangle [x0, x1] x [y0, y1] (inclusive).
    void expectCoverage(const RenderImages& img, int x0, int x1, int y0, int y1)
    {
        int inside = 0, outside = 0;
        for (int y = 0; y < img.height; ++y)
            for (int x = 0; x < img.width; ++x)
            {
                bool in = x >= x0 && x <= x1 && y >= y0 && y <= y1;
                float a = img.alpha[std::size_t(y) * img.width + x];
                if (in && a == 1.0f)
                    ++inside;
                if (!in && a != 0.0f)
                    ++outside;
            }
        EXPECT_EQ(inside, (x1 - x0 + 1) * (y1 - y0 + 1));
        EXPECT_EQ(outside, 0);
    }

    std::string testOut()
    {
        const char* env = std::getenv("TREELOD_TEST_OUT");
        std::string dir = env ? env : std::string(TREELOD_BINARY_DIR) + "/test-out";
        std::filesystem::create_directories(dir);
        return dir;
    }

    bool sameImages(const RenderImages& a, const RenderImages& b)
    {
        return a.width == b.width && a.height == b.height &&
               std::memcmp(a.colour.pixels.data(), b.colour.pixels.data(), a.colour.pixels.size() * sizeof(glm::vec4)) == 0 &&
               std::memcmp(a.alpha.data(), b.alpha.data(), a.alpha.size() * sizeof(float)) == 0 &&
               std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(float)) == 0 &&
               std::memcmp(a.normal.data(), b.normal.data(), a.normal.size() * sizeof(glm::vec3)) == 0;
    }
}

// ---- coverage and camera --------------------------------------------------------------------

TEST(ReferenceRenderer, BarkQuadFillsItsPixelRectangle)
{
    // Quad x in [-1, 1], y in [-0.5, 1]: pixel centres (px + 0.5) / 10 - 2 in [-1, 1] give
    // columns 10..29; centres 2 - (py + 0.5) / 10 in [-0.5, 1] give rows 10..24 (row 0 = top).
    TreeModel m;
    m.materials.push_back(barkMaterial({0.5f, 0.4f, 0.3f}));
    addBarkQuad(m, {-1.0f, -0.5f, 0.0f}, {2.0f, 0.0f, 0.0f}, {0.0f, 1.5f, 0.0f}, 0);
    m.updateBounds();
    ReferenceRenderer renderer(m);
    for (int samples : {1, 4, 16}) // edges lie on pixel borders: supersampling changes nothing
    {
        RenderImages img = renderer.render(frontOrtho(), smallOptions(samples));
        ASSERT_EQ(img.width, 40);
        ASSERT_EQ(img.alpha.size(), 1600u);
        expectCoverage(img, 10, 29, 10, 24);
    }
}

TEST(ReferenceRenderer, PerspectiveRaysMatchTheProjectionMatrix)
{
    // fovY 90 degrees from z = 5: the view spans y (and x) in [-5, 5] at z = 0, so on 50 x 50
    // pixels 1 m = 5 px and the quad x, y in [-1, 1] covers columns and rows 20..29.
    TreeModel m;
    m.materials.push_back(barkMaterial({0.5f, 0.5f, 0.5f}));
    addBarkQuad(m, {-1.0f, -1.0f, 0.0f}, {2.0f, 0.0f, 0.0f}, {0.0f, 2.0f, 0.0f}, 0);
    m.updateBounds();
    CameraSpec cam;
    cam.position = {0.0f, 0.0f, 5.0f};
    cam.target = {0.0f, 0.0f, 0.0f};
    cam.fovYDegrees = 90.0f;
    RenderOptions o = smallOptions();
    o.width = o.height = 50;
    RenderImages img = ReferenceRenderer(m).render(cam, o);
    expectCoverage(img, 20, 29, 20, 29);
    // Depth is the distance along the view axis, not along the ray: 5 m even at a corner pixel.
    EXPECT_NEAR(img.depth[20 * 50 + 20], 5.0f, 1e-4f);
    EXPECT_NEAR(img.depth[25 * 50 + 25], 5.0f, 1e-4f);
}

TEST(ReferenceRenderer, NearAndFarPlanesClipLikeOpenGL)
{
    // The quad at z = 0 is 5 m from the camera: a near plane beyond it or a far plane before it
    // removes it, exactly as clipping does on the GPU.
    TreeModel m;
    m.materials.push_back(barkMaterial({0.5f, 0.5f, 0.5f}));
    addBarkQuad(m, {-1.0f, -1.0f, 0.0f}, {2.0f, 0.0f, 0.0f}, {0.0f, 2.0f, 0.0f}, 0);
    ReferenceRenderer renderer(m);
    CameraSpec cam = frontOrtho();
    cam.nearClip = 5.5f;
    EXPECT_EQ(renderer.render(cam, smallOptions()).alpha[20 * 40 + 20], 0.0f);
    cam.nearClip = 0.1f;
    cam.farClip = 4.5f;
    EXPECT_EQ(renderer.render(cam, smallOptions()).alpha[20 * 40 + 20], 0.0f);
    cam.farClip = 5.5f;
    EXPECT_EQ(renderer.render(cam, smallOptions()).alpha[20 * 40 + 20], 1.0f);
}

// ---- shading ---------------------------------------------------------------------------------

TEST(ReferenceRenderer, BarkColourIsTheAnalyticShading)
{
    // n = (0,0,1), sun = (0, 0.6, 0.8): dot = 0.8. albedo (0.5, 0.4, 0.3), ambient 0.2,
    // sun colour (1, 0.5, 0.25): linear = albedo * (0.2 + sun * 0.8) = (0.5, 0.24, 0.12),
    // which is sRGB (0.73536, 0.52711, 0.38109).
    TreeModel m;
    m.materials.push_back(barkMaterial({0.5f, 0.4f, 0.3f}));
    addBarkQuad(m, {-1.0f, -1.0f, 0.0f}, {2.0f, 0.0f, 0.0f}, {0.0f, 2.0f, 0.0f}, 0);
    RenderImages img = ReferenceRenderer(m).render(frontOrtho(), smallOptions(4));
    glm::vec4 c = img.colour.at(20, 20);
    EXPECT_NEAR(c.r, 0.73536f, 1e-4f);
    EXPECT_NEAR(c.g, 0.52711f, 1e-4f);
    EXPECT_NEAR(c.b, 0.38109f, 1e-4f);
    EXPECT_EQ(c.a, 1.0f);
    EXPECT_NEAR(c.r, srgb(0.5f), 1e-5f);
    // Background is opaque and exactly lighting.background.
    EXPECT_EQ(img.colour.at(0, 0), glm::vec4(0.1f, 0.2f, 0.3f, 1.0f));
}

TEST(ReferenceRenderer, AmbientOcclusionDarkensOnlyTheAmbientTerm)
{
    // With ao = 0.5 at every vertex: linear = albedo * (0.2 * 0.5 + sun * 0.8)
    // = (0.5 * 0.9, 0.4 * 0.5, 0.3 * 0.3) = (0.45, 0.2, 0.09).
    TreeModel m;
    m.materials.push_back(barkMaterial({0.5f, 0.4f, 0.3f}));
    addBarkQuad(m, {-1.0f, -1.0f, 0.0f}, {2.0f, 0.0f, 0.0f}, {0.0f, 2.0f, 0.0f}, 0);
    AmbientOcclusion ao;
    ao.barkVertex.assign(4, 0.5f);
    RenderOptions o = smallOptions();
    o.ambientOcclusion = &ao;
    glm::vec4 c = ReferenceRenderer(m).render(frontOrtho(), o).colour.at(20, 20);
    EXPECT_NEAR(c.r, srgb(0.45f), 1e-4f);
    EXPECT_NEAR(c.g, srgb(0.2f), 1e-4f);
    EXPECT_NEAR(c.b, srgb(0.09f), 1e-4f);
    ao.barkVertex.pop_back(); // wrong size: a programming error, reported
    EXPECT_THROW(ReferenceRenderer(m).render(frontOrtho(), o), std::invalid_argument);
}

TEST(ReferenceRenderer, LeafAlphaTestShowsOnlyTheOpaqueHalfOfTheTexture)
{
    // The texture's left half (u < 0.5) is transparent; the leaf spans x in [-1, 1] with u = (x+1)/2,
    // so only x in [0, 1], columns 20..29, remain. White texel * white base colour: albedo 1,
    // linear (1 * (0.2 + 0.8), 0.2 + 0.4, 0.2 + 0.2) = (1, 0.6, 0.4).
    TreeModel m;
    m.textures.push_back(halfTransparentTexture());
    m.materials.push_back(leafMaterial({1.0f, 1.0f, 1.0f}, {0.0f, 0.0f, 0.0f}, 0));
    addLeafQuad(m, {-1.0f, -1.0f, 0.0f}, {2.0f, 0.0f, 0.0f}, {0.0f, 2.0f, 0.0f}, 0);
    m.updateBounds();
    ASSERT_TRUE(m.validate().ok());
    RenderImages img = ReferenceRenderer(m).render(frontOrtho(), smallOptions());
    expectCoverage(img, 20, 29, 10, 29);
    glm::vec4 c = img.colour.at(25, 20);
    EXPECT_NEAR(c.r, 1.0f, 1e-4f);
    EXPECT_NEAR(c.g, srgb(0.6f), 1e-4f);
    EXPECT_NEAR(c.b, srgb(0.4f), 1e-4f);
}

TEST(ReferenceRenderer, LeafSeenFromBehindUsesBackColourAndFlippedNormal)
{
    // Front faces +Z. From -Z the back is seen: n = (0,0,-1), and with the sun at (0,0,-1)
    // linear = backColour * (0.2 + sun) = (0.2 * 1.2, 0.6 * 0.7, 0.1 * 0.45) = (0.24, 0.42, 0.045).
    // From +Z the front gets no sun (dot = -1): linear = baseColour * 0.2.
    TreeModel m;
    m.materials.push_back(leafMaterial({0.9f, 0.8f, 0.7f}, {0.2f, 0.6f, 0.1f}, -1));
    addLeafQuad(m, {-1.0f, -1.0f, 0.0f}, {2.0f, 0.0f, 0.0f}, {0.0f, 2.0f, 0.0f}, 0);
    m.updateBounds();
    ReferenceRenderer renderer(m);
    RenderOptions o = smallOptions();
    o.lighting.sunDirection = {0.0f, 0.0f, -1.0f};
    o.lighting.sunColour = {1.0f, 0.5f, 0.25f};

    RenderImages back = renderer.render(frontOrtho(-5.0f), o);
    glm::vec4 c = back.colour.at(20, 20);
    EXPECT_NEAR(c.r, srgb(0.24f), 1e-4f);
    EXPECT_NEAR(c.g, srgb(0.42f), 1e-4f);
    EXPECT_NEAR(c.b, srgb(0.045f), 1e-4f);
    EXPECT_EQ(back.normal[20 * 40 + 20], glm::vec3(0.0f, 0.0f, -1.0f));

    RenderImages front = renderer.render(frontOrtho(5.0f), o);
    c = front.colour.at(20, 20);
    EXPECT_NEAR(c.r, srgb(0.9f * 0.2f), 1e-4f);
    EXPECT_NEAR(c.g, srgb(0.8f * 0.2f), 1e-4f);
    EXPECT_NEAR(c.b, srgb(0.7f * 0.2f), 1e-4f);
    EXPECT_EQ(front.normal[20 * 40 + 20], glm::vec3(0.0f, 0.0f, 1.0f));
}

TEST(ReferenceRenderer, LeafSideComesFromItsShadingNormalNotItsWinding)
{
    // Winding faces +Z but the vertex normals say -Z. Seen from +Z, the normal turns away from
    // the camera, so (as in the GLSL) this is the back: n = (0,0,1) and the back colour is used.
    // With the sun at (0,0,1): linear = backColour * (0.2 + sun) = (0.24, 0.42, 0.045).
    TreeModel m;
    m.materials.push_back(leafMaterial({0.9f, 0.8f, 0.7f}, {0.2f, 0.6f, 0.1f}, -1));
    addLeafQuad(m, {-1.0f, -1.0f, 0.0f}, {2.0f, 0.0f, 0.0f}, {0.0f, 2.0f, 0.0f}, 0);
    for (Vertex& v : m.leafVertices)
        v.normal = {0.0f, 0.0f, -1.0f};
    RenderOptions o = smallOptions();
    o.lighting.sunDirection = {0.0f, 0.0f, 1.0f};
    RenderImages img = ReferenceRenderer(m).render(frontOrtho(5.0f), o);
    glm::vec4 c = img.colour.at(20, 20);
    EXPECT_NEAR(c.r, srgb(0.24f), 1e-4f);
    EXPECT_NEAR(c.g, srgb(0.42f), 1e-4f);
    EXPECT_NEAR(c.b, srgb(0.045f), 1e-4f);
    EXPECT_EQ(img.normal[20 * 40 + 20], glm::vec3(0.0f, 0.0f, 1.0f));
}

TEST(ReferenceRenderer, SingleSidedBarkIsCulledFromBehind)
{
    // As the GPU culls back faces: single-sided bark vanishes from behind, double-sided bark
    // shows its back with the normal turned towards the camera.
    TreeModel m;
    m.materials.push_back(barkMaterial({0.5f, 0.5f, 0.5f}, false));
    m.materials.push_back(barkMaterial({0.5f, 0.5f, 0.5f}, true));
    addBarkQuad(m, {-1.0f, 0.0f, 0.0f}, {2.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, 0);  // rows 10..19
    addBarkQuad(m, {-1.0f, -1.0f, 0.0f}, {2.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, 1); // rows 20..29
    RenderImages img = ReferenceRenderer(m).render(frontOrtho(-5.0f), smallOptions());
    expectCoverage(img, 10, 29, 20, 29);
    EXPECT_EQ(img.normal[25 * 40 + 20], glm::vec3(0.0f, 0.0f, -1.0f));
}

// ---- supersampling, depth, normals -------------------------------------------------------------

TEST(ReferenceRenderer, SupersamplingGivesFractionalAlphaOnAnEdge)
{
    // The right edge x = 1.05 splits column 30 (x in [1.0, 1.1]) in half: with 2x2 and 4x4
    // samples, half the sample columns are inside, so alpha = 0.5 and the colour is the mean of
    // quad and background in linear space.
    TreeModel m;
    m.materials.push_back(barkMaterial({0.5f, 0.4f, 0.3f}));
    addBarkQuad(m, {-1.0f, -1.0f, 0.0f}, {2.05f, 0.0f, 0.0f}, {0.0f, 2.0f, 0.0f}, 0);
    ReferenceRenderer renderer(m);
    for (int samples : {4, 16})
    {
        RenderImages img = renderer.render(frontOrtho(), smallOptions(samples));
        EXPECT_EQ(img.alpha[20 * 40 + 30], 0.5f);
        EXPECT_EQ(img.alpha[20 * 40 + 29], 1.0f);
        EXPECT_EQ(img.alpha[20 * 40 + 31], 0.0f);
        glm::vec4 c = img.colour.at(30, 20);
        EXPECT_NEAR(c.r, srgb(0.5f * (0.5f + linear(0.1f))), 1e-4f);
        EXPECT_NEAR(c.b, srgb(0.5f * (0.12f + linear(0.3f))), 1e-4f);
        // depth/normal come from a hitting sample, so they are set on the edge pixel too
        EXPECT_NEAR(img.depth[20 * 40 + 30], 5.0f, 1e-5f);
    }
    EXPECT_THROW(renderer.render(frontOrtho(), smallOptions(3)), std::invalid_argument);
}

TEST(ReferenceRenderer, DepthIsDistanceAlongTheViewAxis)
{
    // Quad at z = 1, camera at z = 5: 4 m; empty pixels are +inf.
    TreeModel m;
    m.materials.push_back(barkMaterial({0.5f, 0.5f, 0.5f}));
    addBarkQuad(m, {-1.0f, -1.0f, 1.0f}, {2.0f, 0.0f, 0.0f}, {0.0f, 2.0f, 0.0f}, 0);
    RenderImages img = ReferenceRenderer(m).render(frontOrtho(), smallOptions(4));
    EXPECT_NEAR(img.depth[20 * 40 + 20], 4.0f, 1e-5f);
    EXPECT_EQ(img.depth[0], std::numeric_limits<float>::infinity());
    EXPECT_EQ(img.normal[0], glm::vec3(0.0f));
}

TEST(ReferenceRenderer, NormalsAreUnitAndFaceTheCamera)
{
    // A tilted quad, vertex normals equal to the face normal: every covered pixel's normal is
    // that unit normal, which points towards the camera (dot with the view direction < 0).
    TreeModel m;
    m.materials.push_back(barkMaterial({0.5f, 0.5f, 0.5f}));
    glm::vec3 u = glm::vec3(1.5f, 0.0f, 0.5f), v = glm::vec3(0.0f, 1.5f, 0.7f);
    addBarkQuad(m, {-0.8f, -0.8f, 0.0f}, u, v, 0);
    glm::vec3 expected = glm::normalize(glm::cross(u, v));
    RenderImages img = ReferenceRenderer(m).render(frontOrtho(), smallOptions(4));
    int covered = 0;
    for (std::size_t p = 0; p < img.alpha.size(); ++p)
        if (img.alpha[p] > 0.0f)
        {
            ++covered;
            EXPECT_NEAR(glm::length(img.normal[p]), 1.0f, 1e-5f);
            EXPECT_LT(glm::length(img.normal[p] - expected), 1e-5f);
            EXPECT_LT(glm::dot(img.normal[p], glm::vec3(0.0f, 0.0f, -1.0f)), 0.0f);
        }
    EXPECT_GT(covered, 100);
}

// ---- robustness -------------------------------------------------------------------------------

TEST(ReferenceRenderer, EmptyModelRendersBackgroundOnly)
{
    TreeModel m; // no triangles at all: Embree gets no geometry
    RenderOptions o = smallOptions(4);
    RenderImages img = ReferenceRenderer(m).render(frontOrtho(), o);
    for (std::size_t p = 0; p < img.alpha.size(); ++p)
    {
        ASSERT_EQ(img.colour.pixels[p], glm::vec4(o.lighting.background, 1.0f));
        ASSERT_EQ(img.alpha[p], 0.0f);
        ASSERT_EQ(img.depth[p], std::numeric_limits<float>::infinity());
    }
    AmbientOcclusion ao = computeAmbientOcclusion(m);
    EXPECT_TRUE(ao.barkVertex.empty() && ao.leafVertex.empty());
}

TEST(ReferenceRenderer, DegenerateAndBrokenTrianglesDoNotCrash)
{
    // A zero-area triangle, a triangle with an out-of-range index (skipped), a NaN vertex, a
    // vertex at 1e30 m (beyond what Embree accepts) and a camera whose position equals its
    // target (background only): nothing is drawn and nothing crashes.
    TreeModel m;
    m.materials.push_back(barkMaterial({0.5f, 0.5f, 0.5f}));
    m.barkVertices = {{{0, 0, 0}}, {{1, 1, 0}}, {{2, 2, 0}}, {{NAN, 0, 0}}, {{1e30f, 0, 0}}};
    m.barkIndices = {0, 1, 2, 0, 1, 7, 0, 1, 3, 0, 1, 4};
    m.barkTriangleMaterial = {0, 0, 5, 0};
    ReferenceRenderer renderer(m);
    RenderImages img = renderer.render(frontOrtho(), smallOptions(4));
    for (float a : img.alpha)
        ASSERT_EQ(a, 0.0f);
    CameraSpec broken = frontOrtho();
    broken.target = broken.position;
    EXPECT_EQ(renderer.render(broken, smallOptions()).alpha[0], 0.0f);
    AmbientOcclusion ao = computeAmbientOcclusion(m);
    ASSERT_EQ(ao.barkVertex.size(), 5u);
    for (float a : ao.barkVertex)
        EXPECT_TRUE(a >= 0.0f && a <= 1.0f);
}

TEST(ReferenceRenderer, TransparentBackgroundKeepsStraightColourAndCoverage)
{
    // The half-covered edge pixel of SupersamplingGivesFractionalAlphaOnAnEdge: without the
    // background the colour is the quad's own (sRGB 0.73536 red) and alpha is 0.5.
    TreeModel m;
    m.materials.push_back(barkMaterial({0.5f, 0.4f, 0.3f}));
    addBarkQuad(m, {-1.0f, -1.0f, 0.0f}, {2.05f, 0.0f, 0.0f}, {0.0f, 2.0f, 0.0f}, 0);
    RenderOptions o = smallOptions(4);
    o.transparentBackground = true;
    RenderImages img = ReferenceRenderer(m).render(frontOrtho(), o);
    EXPECT_NEAR(img.colour.at(30, 20).r, 0.73536f, 1e-4f);
    EXPECT_EQ(img.colour.at(30, 20).a, 0.5f);
    EXPECT_EQ(img.colour.at(0, 0), glm::vec4(0.0f));
}

TEST(ReferenceRenderer, RendersAreDeterministicForAnyThreadCount)
{
    // Pixels are independent and there is no shared RNG: repeated renders and a renderer built
    // and run on one thread give byte-identical images.
    TreeModel m = syntheticTree(400, 1.0f, 0.35f);
    CameraSpec cam = CameraSpec::framing(m.boundsMin, m.boundsMax, 30.0f, 10.0f);
    RenderOptions o;
    o.width = o.height = 96;
    o.samplesPerPixel = 4;
    RenderImages a, b, c;
    {
        ReferenceRenderer renderer(m);
        a = renderer.render(cam, o);
        b = renderer.render(cam, o);
    }
    {
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        ReferenceRenderer renderer(m);
        c = renderer.render(cam, o);
    }
    EXPECT_TRUE(sameImages(a, b));
    EXPECT_TRUE(sameImages(a, c));
}

TEST(ReferenceRenderer, TinyAndHugeTreesRenderAlike)
{
    // The same tree at 0.5 m and 500 m, each framed by its own bounds, covers the same pixels:
    // nothing in the renderer depends on absolute size. (Float rounding of the scaled vertices
    // may flip a few edge samples, hence a small tolerance.)
    RenderOptions o;
    o.width = o.height = 64;
    o.samplesPerPixel = 4;
    double sums[2] = {0.0, 0.0};
    RenderImages imgs[2];
    int i = 0;
    for (float scale : {0.5f / 5.8f, 500.0f / 5.8f})
    {
        TreeModel m = syntheticTree(300, scale, 0.35f);
        CameraSpec cam = CameraSpec::framing(m.boundsMin, m.boundsMax, 0.0f, 0.0f);
        imgs[i] = ReferenceRenderer(m).render(cam, o);
        for (float a : imgs[i].alpha)
            sums[i] += a;
        ++i;
    }
    EXPECT_GT(sums[0], 200.0);
    EXPECT_NEAR(sums[0], sums[1], 0.005 * sums[0]);
    int differing = 0;
    for (std::size_t p = 0; p < imgs[0].alpha.size(); ++p)
        differing += std::abs(imgs[0].alpha[p] - imgs[1].alpha[p]) > 0.3f;
    EXPECT_LT(differing, 20);
}

// ---- ambient occlusion ------------------------------------------------------------------------

namespace
{
    /// A 0.2 m bark quad at y = 0 facing up, optionally under a 20 x 20 m plane at y = 0.5.
    TreeModel groundPatch(bool roof, bool roofIsTransparentLeaf, bool patchIsLeaf)
    {
        TreeModel m;
        m.materials.push_back(barkMaterial({0.5f, 0.5f, 0.5f}));
        m.textures.push_back(halfTransparentTexture());
        m.textures.back().rgba.assign(m.textures.back().rgba.size(), 0); // fully transparent
        m.materials.push_back(leafMaterial({1.0f, 1.0f, 1.0f}, {}, 0));
        m.materials.push_back(leafMaterial({1.0f, 1.0f, 1.0f}, {}, -1));
        glm::vec3 corner(-0.1f, 0.0f, 0.1f), u(0.2f, 0.0f, 0.0f), v(0.0f, 0.0f, -0.2f); // faces +Y
        if (patchIsLeaf)
            addLeafQuad(m, corner, u, v, 2);
        else
            addBarkQuad(m, corner, u, v, 0);
        if (roof)
        {
            glm::vec3 rc(-10.0f, 0.5f, -10.0f), ru(20.0f, 0.0f, 0.0f), rv(0.0f, 0.0f, 20.0f); // faces -Y
            if (roofIsTransparentLeaf)
                addLeafQuad(m, rc, ru, rv, 1);
            else
                addBarkQuad(m, rc, ru, rv, 0);
        }
        m.updateBounds();
        return m;
    }
}

TEST(AmbientOcclusion, OpenPointIsUnoccludedAndRoofedPointIsDark)
{
    // Alone, nothing can block a ray: exactly 1. Under a plane 0.5 m above that reaches 10 m
    // to each side, only directions within ~3 degrees of the horizon escape: cosine-weighted
    // that is sin^2(2.9 deg) < 0.01 of the hemisphere.
    AoOptions opts;
    opts.maxDistance = 50.0f;
    AmbientOcclusion open = computeAmbientOcclusion(groundPatch(false, false, false), opts);
    ASSERT_EQ(open.barkVertex.size(), 4u);
    for (float a : open.barkVertex)
        EXPECT_EQ(a, 1.0f);
    AmbientOcclusion roofed = computeAmbientOcclusion(groundPatch(true, false, false), opts);
    ASSERT_EQ(roofed.barkVertex.size(), 8u);
    for (int i = 0; i < 4; ++i)
        EXPECT_LT(roofed.barkVertex[i], 0.1f);
}

TEST(AmbientOcclusion, LeafCornersAverageBothHemispheres)
{
    // A leaf under the roof: its upper hemisphere is blocked, its lower one is open, so the
    // two-sided mean is about 0.5.
    AoOptions opts;
    opts.maxDistance = 50.0f;
    AmbientOcclusion ao = computeAmbientOcclusion(groundPatch(true, false, true), opts);
    ASSERT_EQ(ao.leafVertex.size(), 4u);
    for (float a : ao.leafVertex)
    {
        EXPECT_GT(a, 0.45f);
        EXPECT_LT(a, 0.55f);
    }
}

TEST(AmbientOcclusion, AlphaTestedLeavesOccludeOnlyWhereOpaque)
{
    // The roof is a leaf whose texture is fully transparent: every occlusion ray passes.
    AoOptions opts;
    opts.maxDistance = 50.0f;
    AmbientOcclusion ao = computeAmbientOcclusion(groundPatch(true, true, false), opts);
    for (int i = 0; i < 4; ++i)
        EXPECT_EQ(ao.barkVertex[i], 1.0f);
}

TEST(AmbientOcclusion, DeterministicForAnyThreadCountAndSizeIndependent)
{
    // Directions depend only on (seed, point index): one thread gives the same bytes. The same
    // tree at 0.5 m and 500 m (epsilons and default ray length relative to the bounds) agrees
    // up to a few rays flipped by rounding.
    TreeModel m = syntheticTree(200, 1.0f, 0.35f);
    AoOptions opts;
    opts.raysPerPoint = 32;
    AmbientOcclusion a = computeAmbientOcclusion(m, opts);
    AmbientOcclusion b;
    {
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        b = computeAmbientOcclusion(m, opts);
    }
    EXPECT_EQ(a.barkVertex, b.barkVertex);
    EXPECT_EQ(a.leafVertex, b.leafVertex);

    double mean = 0.0, diff = 0.0;
    AmbientOcclusion tiny = computeAmbientOcclusion(syntheticTree(200, 0.5f / 5.8f, 0.35f), opts);
    AmbientOcclusion huge = computeAmbientOcclusion(syntheticTree(200, 500.0f / 5.8f, 0.35f), opts);
    for (std::size_t i = 0; i < tiny.leafVertex.size(); ++i)
    {
        mean += tiny.leafVertex[i];
        diff += std::abs(tiny.leafVertex[i] - huge.leafVertex[i]);
    }
    mean /= double(tiny.leafVertex.size());
    diff /= double(tiny.leafVertex.size());
    EXPECT_GT(mean, 0.3); // the crown is sparse but not empty
    EXPECT_LT(mean, 0.99);
    EXPECT_LT(diff, 0.01);
    // A different seed changes the directions, so some values change.
    opts.seed = 2;
    EXPECT_NE(computeAmbientOcclusion(m, opts).leafVertex, a.leafVertex);
}

TEST(AmbientOcclusion, ArbitraryPointsUseTheSameRules)
{
    // computeAmbientOcclusionAt at the roofed patch's first corner (one-sided, normal +Y)
    // equals the per-vertex result for that corner, which is point 0 in both calls.
    AoOptions opts;
    opts.maxDistance = 50.0f;
    TreeModel m = groundPatch(true, false, false);
    AmbientOcclusion all = computeAmbientOcclusion(m, opts);
    std::vector<float> at = computeAmbientOcclusionAt(m, {{m.barkVertices[0].position, {0, 1, 0}, false}}, opts);
    ASSERT_EQ(at.size(), 1u);
    EXPECT_EQ(at[0], all.barkVertex[0]);
}

// ---- a picture to look at ------------------------------------------------------------------------

TEST(ReferenceRenderer, WritesASyntheticTreeImage)
{
    // Not a golden test: writes PNGs to TREELOD_TEST_OUT for a person to open (colour without
    // and with AO, the AO term alone, coverage), and checks the tree is where the framing camera puts it.
    TreeModel m = syntheticTree(1500, 1.0f, 0.3f);
    ReferenceRenderer renderer(m);
    CameraSpec cam = CameraSpec::framing(m.boundsMin, m.boundsMax, 20.0f, 10.0f);
    RenderOptions o;
    o.width = o.height = 256;
    o.samplesPerPixel = 4;
    RenderImages plain = renderer.render(cam, o);
    AmbientOcclusion ao = computeAmbientOcclusion(m);
    o.ambientOcclusion = &ao;
    RenderImages shaded = renderer.render(cam, o);
    RenderOptions aoOnly = o; // white ambient, no sun: the AO term itself
    aoOnly.lighting.sunColour = glm::vec3(0.0f);
    aoOnly.lighting.ambientColour = glm::vec3(1.0f);
    RenderImages occlusion = renderer.render(cam, aoOnly);
    Image coverage(o.width, o.height);
    for (std::size_t p = 0; p < plain.alpha.size(); ++p)
        coverage.pixels[p] = glm::vec4(glm::vec3(plain.alpha[p]), 1.0f);
    std::string dir = testOut();
    ASSERT_TRUE(writePng(dir + "/renderer_tree.png", plain.colour).ok());
    ASSERT_TRUE(writePng(dir + "/renderer_tree_ao.png", shaded.colour).ok());
    ASSERT_TRUE(writePng(dir + "/renderer_tree_alpha.png", coverage).ok());
    ASSERT_TRUE(writePng(dir + "/renderer_tree_ao_only.png", occlusion.colour).ok());
    double covered = 0.0;
    for (float a : plain.alpha)
        covered += a;
    EXPECT_GT(covered / plain.alpha.size(), 0.1); // the crown fills a good part of the frame
    EXPECT_EQ(plain.alpha[0], 0.0f);              // corners stay sky
}
