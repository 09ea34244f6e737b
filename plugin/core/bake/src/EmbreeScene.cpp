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

        float wrapUnit(float x)
        {
            if (!std::isfinite(x))
                return 0.0f;
            x -= std::floor(x);
            return x < 1.0f ? x : 0.0f; // floor rounding can give exactly 1
        }
    }

    glm::vec4 LinearTexture::sample(glm::vec2 uv) const
    {
        if (width <= 0 || height <= 0)
            return glm::vec4(1.0f);
        float x = wrapUnit(uv.x) * float(width) - 0.5f;
        float y = wrapUnit(uv.y) * float(height) - 0.5f;
        float fx = std::floor(x), fy = std::floor(y);
        float ax = x - fx, ay = y - fy;
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
        const glm::vec4* row0 = &texels[std::size_t(y0) * width];
        const glm::vec4* row1 = &texels[std::size_t(y1) * width];
        glm::vec4 top = row0[x0] + (row0[x1] - row0[x0]) * ax;
        glm::vec4 bottom = row1[x0] + (row1[x1] - row1[x0]) * ax;
        return top + (bottom - top) * ay;
    }

    EmbreeScene::EmbreeScene(const TreeModel& model) : mModel(model)
    {
        mMaterials = model.materials;
        mMaterials.push_back(Material{}); // default for out-of-range references
        mMaterials.back().name = "default";

        // Textures: sRGB colour decoded once through a table, straight alpha.
        float decode[256];
        for (int i = 0; i < 256; ++i)
            decode[i] = srgbToLinear(float(i) / 255.0f);
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
            for (std::size_t p = 0; p < count; ++p)
            {
                const std::uint8_t* c = &src.rgba[p * 4];
                dst.texels[p] = glm::vec4(decode[c[0]], decode[c[1]], decode[c[2]], float(c[3]) / 255.0f);
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
        const Triangle& tri = mTriangles[Leaves][prim];
        const Material& m = mMaterials[tri.material];
        float alpha = m.baseColour.a;
        if (const LinearTexture* tex = texture(m))
        {
            const std::vector<Vertex>& vs = mModel.leafVertices;
            glm::vec2 uv = (1.0f - u - v) * vs[tri.v[0]].uv + u * vs[tri.v[1]].uv + v * vs[tri.v[2]].uv;
            alpha *= tex->sample(uv).a;
        }
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
            const Material& m = self->mMaterials[self->mTriangles[Leaves][prim].material];
            if (self->leafAlpha(prim, u, v) < m.alphaCutoff)
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
