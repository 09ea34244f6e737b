#include "EmbreeScene.h"

#include "TreeLod/Image.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace TreeLod
{
    namespace
    {
        /// The intersect context plus what the filters need to know about the query.
        struct QueryContext
        {
            RTCIntersectContext base; // first member: Embree hands back a pointer to it
            bool cameraRay;           // true: cull single-sided bark from behind
        };

        void throwOnError(RTCDevice device, const char* what)
        {
            RTCError err = rtcGetDeviceError(device);
            if (err != RTC_ERROR_NONE)
                throw std::runtime_error(std::string("Embree: ") + what + " failed (error " +
                                         std::to_string(int(err)) + ")");
        }

        /// Embree (Debian builds keep its assertions) accepts ray components up to about 1.8e18.
        bool rayable(const glm::vec3& v)
        {
            constexpr float limit = 1e18f;
            return std::abs(v.x) <= limit && std::abs(v.y) <= limit && std::abs(v.z) <= limit; // false for NaN
        }

        float wrapUnit(float x)
        {
            if (!std::isfinite(x))
                return 0.0f;
            x -= std::floor(x);
            return x < 1.0f ? x : 0.0f; // floor rounding can give exactly 1
        }
    }

    namespace
    {
        /// The four texels around uv (bilinear footprint) with REPEAT wrapping.
        struct Footprint
        {
            std::size_t i00, i10, i01, i11; ///< texel indices: (x0,y0), (x1,y0), (x0,y1), (x1,y1)
            float ax, ay;                   ///< weights of x1 and y1
        };

        Footprint footprint(glm::vec2 uv, int width, int height)
        {
            float x = wrapUnit(uv.x) * float(width) - 0.5f;
            float y = wrapUnit(uv.y) * float(height) - 0.5f;
            float fx = std::floor(x), fy = std::floor(y);
            int x0 = int(fx), y0 = int(fy);
            int x1 = x0 + 1, y1 = y0 + 1;
            if (x0 < 0)
                x0 += width;
            if (y0 < 0)
                y0 += height;
            if (x1 >= width)
                x1 -= width;
            if (y1 >= height)
                y1 -= height;
            std::size_t r0 = std::size_t(y0) * width, r1 = std::size_t(y1) * width;
            return {r0 + x0, r0 + x1, r1 + x0, r1 + x1, x - fx, y - fy};
        }
    }

    glm::vec4 LinearTexture::sample(glm::vec2 uv) const
    {
        if (width <= 0 || height <= 0)
            return glm::vec4(1.0f);
        Footprint f = footprint(uv, width, height);
        glm::vec4 top = texels[f.i00] + (texels[f.i10] - texels[f.i00]) * f.ax;
        glm::vec4 bottom = texels[f.i01] + (texels[f.i11] - texels[f.i01]) * f.ax;
        return top + (bottom - top) * f.ay;
    }

    float LinearTexture::sampleAlpha(glm::vec2 uv) const
    {
        if (width <= 0 || height <= 0)
            return 1.0f;
        Footprint f = footprint(uv, width, height);
        constexpr float scale = 1.0f / 255.0f;
        float a00 = alpha[f.i00] * scale, a10 = alpha[f.i10] * scale;
        float a01 = alpha[f.i01] * scale, a11 = alpha[f.i11] * scale;
        float top = a00 + (a10 - a00) * f.ax;
        float bottom = a01 + (a11 - a01) * f.ax;
        return top + (bottom - top) * f.ay;
    }

    EmbreeScene::EmbreeScene(const TreeModel& model) : mModel(model)
    {
        mMaterials = model.materials;
        mMaterials.push_back(Material{}); // default for out-of-range references
        mMaterials.back().name = "default";

        // Textures: sRGB colour decoded once through a table, straight alpha.
        mTextures.resize(model.textures.size());
        for (std::size_t i = 0; i < model.textures.size(); ++i)
        {
            const TextureImage& src = model.textures[i];
            std::size_t count = std::size_t(std::max(src.width, 0)) * std::size_t(std::max(src.height, 0));
            if (count == 0 || src.rgba.size() < count * 4)
                continue; // unusable: texture() returns nullptr
            LinearTexture& dst = mTextures[i];
            dst.width = src.width;
            dst.height = src.height;
            dst.texels.resize(count);
            dst.alpha.resize(count);
            for (std::size_t p = 0; p < count; ++p)
            {
                const std::uint8_t* c = &src.rgba[p * 4];
                dst.texels[p] = glm::vec4(srgbByteToLinear(c[0]), srgbByteToLinear(c[1]), srgbByteToLinear(c[2]),
                                          float(c[3]) * (1.0f / 255.0f));
                dst.alpha[p] = c[3];
            }
        }

        mSingleSided.resize(mMaterials.size());
        for (std::size_t i = 0; i < mMaterials.size(); ++i)
            mSingleSided[i] = !mMaterials[i].doubleSided;

        // Triangles with in-range indices only, so Embree never reads out of bounds.
        std::uint32_t defaultMaterial = std::uint32_t(mMaterials.size() - 1);
        auto faceNormal = [](const std::vector<Vertex>& vs, const std::uint32_t* v) {
            glm::vec3 n = glm::cross(vs[v[1]].position - vs[v[0]].position, vs[v[2]].position - vs[v[0]].position);
            float len = glm::length(n);
            return len > 0.0f && std::isfinite(len) ? n / len : glm::vec3(0.0f);
        };
        std::size_t barkVertexCount = model.barkVertices.size();
        for (std::size_t t = 0; t < model.barkIndices.size() / 3; ++t)
        {
            Triangle tri;
            bool ok = true;
            for (int k = 0; k < 3; ++k)
            {
                tri.v[k] = model.barkIndices[t * 3 + k];
                ok = ok && tri.v[k] < barkVertexCount;
            }
            if (!ok)
                continue;
            tri.material = t < model.barkTriangleMaterial.size() && model.barkTriangleMaterial[t] < defaultMaterial
                               ? model.barkTriangleMaterial[t]
                               : defaultMaterial;
            tri.faceNormal = faceNormal(model.barkVertices, tri.v);
            mTriangles[Bark].push_back(tri);
        }
        std::size_t leafVertexCount = model.leafVertices.size();
        for (const Leaf& leaf : model.leaves)
        {
            std::uint32_t material = leaf.material < defaultMaterial ? leaf.material : defaultMaterial;
            std::size_t end = std::min<std::size_t>(std::size_t(leaf.firstIndex) + leaf.indexCount,
                                                    model.leafIndices.size());
            for (std::size_t i = leaf.firstIndex; i + 3 <= end; i += 3)
            {
                Triangle tri;
                bool ok = true;
                for (int k = 0; k < 3; ++k)
                {
                    tri.v[k] = model.leafIndices[i + k];
                    ok = ok && tri.v[k] < leafVertexCount;
                }
                if (!ok)
                    continue;
                tri.material = material;
                tri.faceNormal = faceNormal(model.leafVertices, tri.v);
                mTriangles[Leaves].push_back(tri);
                const Material& m = mMaterials[material];
                AlphaTest test;
                for (int k = 0; k < 3; ++k)
                    test.uv[k] = model.leafVertices[tri.v[k]].uv;
                test.texture = texture(m);
                test.baseAlpha = m.baseColour.a;
                test.cutoff = m.alphaCutoff;
                mAlphaTests.push_back(test);
            }
        }

        glm::vec3 lo(INFINITY), hi(-INFINITY);
        for (const auto* vs : {&model.barkVertices, &model.leafVertices})
            for (const Vertex& v : *vs)
                if (std::isfinite(v.position.x) && std::isfinite(v.position.y) && std::isfinite(v.position.z))
                {
                    lo = glm::min(lo, v.position);
                    hi = glm::max(hi, v.position);
                }
        mDiagonal = lo.x <= hi.x ? glm::length(hi - lo) : 0.0f;
        if (!std::isfinite(mDiagonal))
            mDiagonal = 0.0f;

        mDevice = rtcNewDevice(nullptr);
        if (!mDevice)
            throw std::runtime_error("Embree: cannot create a device (error " +
                                     std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
        mScene = rtcNewScene(mDevice);
        // Robust: no ray slips between two triangles sharing an edge (e.g. a quad's diagonal).
        rtcSetSceneFlags(mScene, RTC_SCENE_FLAG_ROBUST);
        rtcSetSceneBuildQuality(mScene, RTC_BUILD_QUALITY_HIGH);
        addGeometry(Bark, model.barkVertices);
        addGeometry(Leaves, model.leafVertices);
        rtcCommitScene(mScene);
        throwOnError(mDevice, "building the scene");
    }

    EmbreeScene::~EmbreeScene()
    {
        if (mScene)
            rtcReleaseScene(mScene);
        if (mDevice)
            rtcReleaseDevice(mDevice);
    }

    void EmbreeScene::addGeometry(Part part, const std::vector<Vertex>& vertices)
    {
        const std::vector<Triangle>& tris = mTriangles[part];
        if (tris.empty())
            return;
        RTCGeometry geom = rtcNewGeometry(mDevice, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* pos = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                 3 * sizeof(float), vertices.size()));
        auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                    3 * sizeof(unsigned), tris.size()));
        throwOnError(mDevice, "allocating geometry buffers");
        for (std::size_t i = 0; i < vertices.size(); ++i)
        {
            pos[i * 3 + 0] = vertices[i].position.x;
            pos[i * 3 + 1] = vertices[i].position.y;
            pos[i * 3 + 2] = vertices[i].position.z;
        }
        for (std::size_t i = 0; i < tris.size(); ++i)
            for (int k = 0; k < 3; ++k)
                idx[i * 3 + k] = tris[i].v[k];
        rtcSetGeometryUserData(geom, this);
        if (part == Leaves)
        {
            rtcSetGeometryIntersectFilterFunction(geom, &EmbreeScene::leafFilter);
            rtcSetGeometryOccludedFilterFunction(geom, &EmbreeScene::leafFilter);
        }
        else
        {
            bool anySingleSided = false;
            for (const Triangle& t : tris)
                anySingleSided = anySingleSided || mSingleSided[t.material];
            if (anySingleSided)
                rtcSetGeometryIntersectFilterFunction(geom, &EmbreeScene::barkCullFilter);
        }
        rtcCommitGeometry(geom);
        rtcAttachGeometryByID(mScene, geom, unsigned(part));
        rtcReleaseGeometry(geom);
        throwOnError(mDevice, "adding a geometry");
    }

    const LinearTexture* EmbreeScene::texture(const Material& material) const
    {
        if (material.texture < 0 || std::size_t(material.texture) >= mTextures.size())
            return nullptr;
        const LinearTexture& t = mTextures[std::size_t(material.texture)];
        return t.texels.empty() ? nullptr : &t;
    }

    float EmbreeScene::leafAlpha(std::uint32_t prim, float u, float v) const
    {
        const AlphaTest& test = mAlphaTests[prim];
        float alpha = test.baseAlpha;
        if (test.texture)
            alpha *= test.texture->sampleAlpha((1.0f - u - v) * test.uv[0] + u * test.uv[1] + v * test.uv[2]);
        return alpha;
    }

    void EmbreeScene::leafFilter(const RTCFilterFunctionNArguments* args)
    {
        const auto* self = static_cast<const EmbreeScene*>(args->geometryUserPtr);
        for (unsigned i = 0; i < args->N; ++i)
        {
            if (args->valid[i] != -1)
                continue;
            std::uint32_t prim = RTCHitN_primID(args->hit, args->N, i);
            float u = RTCHitN_u(args->hit, args->N, i), v = RTCHitN_v(args->hit, args->N, i);
            if (self->leafAlpha(prim, u, v) < self->mAlphaTests[prim].cutoff)
                args->valid[i] = 0; // discarded: the ray goes on
        }
    }

    void EmbreeScene::barkCullFilter(const RTCFilterFunctionNArguments* args)
    {
        const auto* context = reinterpret_cast<const QueryContext*>(args->context);
        if (!context->cameraRay)
            return;
        const auto* self = static_cast<const EmbreeScene*>(args->geometryUserPtr);
        for (unsigned i = 0; i < args->N; ++i)
        {
            if (args->valid[i] != -1)
                continue;
            const Triangle& tri = self->mTriangles[Bark][RTCHitN_primID(args->hit, args->N, i)];
            glm::vec3 dir(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                          RTCRayN_dir_z(args->ray, args->N, i));
            if (self->mSingleSided[tri.material] && glm::dot(tri.faceNormal, dir) > 0.0f)
                args->valid[i] = 0; // back face of single-sided bark
        }
    }

    EmbreeScene::Hit EmbreeScene::intersect(const glm::vec3& org, const glm::vec3& dir, float tnear,
                                            float tfar) const
    {
        if (!rayable(org) || !rayable(dir) || !(tnear <= tfar))
            return Hit{};
        QueryContext context;
        rtcInitIntersectContext(&context.base);
        context.cameraRay = true;
        RTCRayHit rh;
        rh.ray.org_x = org.x;
        rh.ray.org_y = org.y;
        rh.ray.org_z = org.z;
        rh.ray.tnear = tnear;
        rh.ray.dir_x = dir.x;
        rh.ray.dir_y = dir.y;
        rh.ray.dir_z = dir.z;
        rh.ray.time = 0.0f;
        rh.ray.tfar = tfar;
        rh.ray.mask = 0xFFFFFFFFu;
        rh.ray.id = 0;
        rh.ray.flags = 0;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(mScene, &context.base, &rh);
        Hit hit;
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
            return hit;
        hit.valid = true;
        hit.part = Part(rh.hit.geomID);
        hit.prim = rh.hit.primID;
        hit.u = rh.hit.u;
        hit.v = rh.hit.v;
        hit.t = rh.ray.tfar;
        return hit;
    }

    bool EmbreeScene::occluded(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar) const
    {
        if (!rayable(org) || !rayable(dir) || !(tnear <= tfar))
            return false;
        QueryContext context;
        rtcInitIntersectContext(&context.base);
        context.cameraRay = false;
        RTCRay ray;
        ray.org_x = org.x;
        ray.org_y = org.y;
        ray.org_z = org.z;
        ray.tnear = tnear;
        ray.dir_x = dir.x;
        ray.dir_y = dir.y;
        ray.dir_z = dir.z;
        ray.time = 0.0f;
        ray.tfar = tfar;
        ray.mask = 0xFFFFFFFFu;
        ray.id = 0;
        ray.flags = 0;
        rtcOccluded1(mScene, &context.base, &ray);
        return ray.tfar < 0.0f; // Embree sets tfar = -inf when occluded
    }
}
