// glTF import: tiny files built in code (GltfTestUtil), one behaviour per test.
#include "AllocationTracker.h"
#include "GltfTestUtil.h"

#include "TreeLod/GltfExporter.h"
#include "TreeLod/GltfImporter.h"
#include "TreeLod/TreeGenerator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>

using namespace TreeLod;
using namespace TreeLod::test;

namespace
{
    Result<TreeModel> importBuilt(const GltfBuilder& b, ImportReport* report = nullptr,
                                  const ImportOptions& options = {})
    {
        std::vector<std::uint8_t> bytes = b.glb();
        return importGltfFromMemory(bytes.data(), bytes.size(), "test.glb", "", options, report);
    }

    Result<TreeModel> importText(const std::string& text, const std::string& baseDir = "", ImportReport* report = nullptr)
    {
        return importGltfFromMemory(reinterpret_cast<const std::uint8_t*>(text.data()), text.size(), "test.gltf",
                                    baseDir, {}, report);
    }

    bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

    void expectNear(const glm::vec3& a, const glm::vec3& b, float eps = 1e-5f)
    {
        EXPECT_NEAR(a.x, b.x, eps);
        EXPECT_NEAR(a.y, b.y, eps);
        EXPECT_NEAR(a.z, b.z, eps);
    }

    /// A unit quad in the XY plane facing +Z, centred at c.
    Quad unitQuad(const glm::vec3& c) { return makeQuad(c, {0.5f, 0, 0}, {0, 0.5f, 0}); }

    /// A one-triangle bark primitive.
    PrimitiveData barkTriangle(int material)
    {
        PrimitiveData d;
        d.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
        d.indices = {0, 1, 2};
        d.material = material;
        return d;
    }
}

// ---- leaves ------------------------------------------------------------------------------

TEST(GltfImporter, OneQuadIsOneLeafWithItsRecord)
{
    GltfBuilder b;
    PrimitiveData d;
    d.material = b.addMaterial("Leaf", "MASK");
    d.add(unitQuad({0, 1, 0}));
    b.addMeshNode("Leaves", d);

    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    // The quad's two triangles share indices 0 and 2: one component, area 1 x 1, facing +Z.
    ASSERT_EQ(model->leaves.size(), 1u);
    const Leaf& leaf = model->leaves[0];
    EXPECT_EQ(leaf.vertexCount, 4u);
    EXPECT_EQ(leaf.indexCount, 6u);
    EXPECT_NEAR(leaf.area, 1.0f, 1e-6f);
    expectNear(leaf.centre, {0, 1, 0});
    expectNear(leaf.normal, {0, 0, 1});
    EXPECT_EQ(leaf.uvMin, glm::vec2(0, 0));
    EXPECT_EQ(leaf.uvMax, glm::vec2(1, 1));
    EXPECT_TRUE(model->materials[leaf.material].isLeaf);
    EXPECT_EQ(model->name, "test");
    EXPECT_TRUE(model->barkVertices.empty());
    expectNear(model->boundsMin, {-0.5f, 0.5f, 0});
    expectNear(model->boundsMax, {0.5f, 1.5f, 0});
}

TEST(GltfImporter, ThreeSeparateQuadsAreThreeLeavesInFileOrder)
{
    GltfBuilder b;
    PrimitiveData d;
    d.material = b.addMaterial("Leaf", "BLEND");
    d.add(unitQuad({0, 0, 0}));
    d.add(unitQuad({5, 0, 0}));
    d.add(unitQuad({-5, 0, 0}));
    b.addMeshNode("Leaves", d);

    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    // No shared index or position between the quads; order is the order of first triangles.
    ASSERT_EQ(model->leaves.size(), 3u);
    EXPECT_NEAR(model->leaves[0].centre.x, 0.0f, 1e-6f);
    EXPECT_NEAR(model->leaves[1].centre.x, 5.0f, 1e-6f);
    EXPECT_NEAR(model->leaves[2].centre.x, -5.0f, 1e-6f);
    for (const Leaf& leaf : model->leaves)
        EXPECT_EQ(leaf.indexCount, 6u);
}

TEST(GltfImporter, CrossedQuadSharingItsMiddleEdgeIsOneLeaf)
{
    // Two quads crossing on the Y axis, each drawn as two halves that meet at x=0 (z=0):
    // the four halves have their own vertices (and the second quad its own primitive),
    // but all share the positions (0,0,0) and (0,1,0).
    GltfBuilder b;
    int leaf = b.addMaterial("Leaf", "MASK");
    PrimitiveData xy, zy;
    xy.material = zy.material = leaf;
    xy.add(makeQuad({-0.25f, 0.5f, 0}, {0.25f, 0, 0}, {0, 0.5f, 0}));
    xy.add(makeQuad({0.25f, 0.5f, 0}, {0.25f, 0, 0}, {0, 0.5f, 0}));
    zy.add(makeQuad({0, 0.5f, -0.25f}, {0, 0, 0.25f}, {0, 0.5f, 0}));
    zy.add(makeQuad({0, 0.5f, 0.25f}, {0, 0, 0.25f}, {0, 0.5f, 0}));
    b.addMeshNode("Leaves", xy);
    b.addMeshNode("Leaves2", zy);

    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    ASSERT_EQ(model->leaves.size(), 1u);
    EXPECT_EQ(model->leaves[0].indexCount, 8u * 3u);
    EXPECT_EQ(model->leaves[0].vertexCount, 16u);
    EXPECT_NEAR(model->leaves[0].area, 2.0f, 1e-5f);
}

TEST(GltfImporter, QuadsThatOnlyIntersectAreSeparateLeaves)
{
    // Crossing at their centres without a common vertex position: not connected.
    GltfBuilder b;
    PrimitiveData d;
    d.material = b.addMaterial("Leaf", "MASK");
    d.add(makeQuad({0, 0.5f, 0}, {0.5f, 0, 0}, {0, 0.5f, 0}));
    d.add(makeQuad({0, 0.5f, 0}, {0, 0, 0.5f}, {0, 0.5f, 0}));
    b.addMeshNode("Leaves", d);

    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    EXPECT_EQ(model->leaves.size(), 2u);
}

TEST(GltfImporter, MultiTriangleLeafIsOneLeaf)
{
    // A fan of 5 triangles around vertex 0 (indexed TRIANGLES): connected through vertex 0.
    GltfBuilder b;
    PrimitiveData d;
    d.material = b.addMaterial("Leaf", "MASK");
    d.positions.push_back({0, 0, 0});
    for (int i = 0; i <= 5; ++i)
    {
        float a = float(i) * 0.5f;
        d.positions.push_back({std::cos(a), std::sin(a), 0});
    }
    for (std::uint32_t i = 1; i <= 5; ++i)
        d.indices.insert(d.indices.end(), {0, i, i + 1});
    b.addMeshNode("Leaves", d);

    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    ASSERT_EQ(model->leaves.size(), 1u);
    EXPECT_EQ(model->leaves[0].indexCount, 15u);
    EXPECT_EQ(model->leaves[0].vertexCount, 7u);
}

TEST(GltfImporter, ZeroAreaLeafIsDroppedAndCounted)
{
    GltfBuilder b;
    PrimitiveData d;
    d.material = b.addMaterial("Leaf", "MASK");
    d.add(makeQuad({3, 0, 0}, {0.5f, 0, 0}, {0, 0, 0})); // all four corners on one line
    d.add(unitQuad({0, 0, 0}));
    b.addMeshNode("Leaves", d);

    ImportReport report;
    auto model = importBuilt(b, &report);
    ASSERT_TRUE(model) << model.error().message();
    ASSERT_EQ(model->leaves.size(), 1u);
    EXPECT_NEAR(model->leaves[0].centre.x, 0.0f, 1e-6f);
    EXPECT_EQ(report.droppedDegenerateLeaves, 1u);
    EXPECT_EQ(model->leafVertices.size(), 4u); // the dropped leaf's vertices are gone too
}

TEST(GltfImporter, DuplicateLeavesAreKeptAndCounted)
{
    GltfBuilder b;
    PrimitiveData d;
    d.material = b.addMaterial("Leaf", "MASK");
    d.add(unitQuad({0, 0, 0}));
    d.add(unitQuad({2, 0, 0}));
    d.add(unitQuad({0, 0, 0})); // exact copy of the first, own vertices
    b.addMeshNode("Leaves", d);

    ImportReport report;
    auto model = importBuilt(b, &report);
    ASSERT_TRUE(model) << model.error().message();
    // The copy shares every position with the first quad, yet stays a leaf of its own.
    EXPECT_EQ(model->leaves.size(), 3u);
    EXPECT_EQ(report.duplicateLeaves, 1u);
    EXPECT_EQ(report.droppedDegenerateLeaves, 0u);
}

TEST(GltfImporter, LeafIndicesAreAbsoluteAndInsideTheLeafRange)
{
    GltfBuilder b;
    PrimitiveData d;
    d.material = b.addMaterial("Leaf", "MASK");
    d.add(unitQuad({0, 0, 0}));
    d.add(unitQuad({2, 0, 0}));
    b.addMeshNode("Leaves", d);

    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    ASSERT_EQ(model->leaves.size(), 2u);
    const Leaf& second = model->leaves[1];
    EXPECT_EQ(second.firstVertex, 4u);
    EXPECT_EQ(second.firstIndex, 6u);
    for (std::uint32_t k = second.firstIndex; k < second.firstIndex + second.indexCount; ++k)
    {
        EXPECT_GE(model->leafIndices[k], 4u);
        EXPECT_LT(model->leafIndices[k], 8u);
    }
}

// ---- geometry ----------------------------------------------------------------------------

TEST(GltfImporter, NodeTranslationRotationAndScaleApply)
{
    // parent: translate (10,0,0); child: rotate 90 degrees about +Y, scale 2.
    // (1,0,0) -> scale (2,0,0) -> rotate (0,0,-2) -> translate (10,0,-2).
    GltfBuilder b;
    PrimitiveData d = barkTriangle(b.addMaterial("Bark", "OPAQUE"));
    d.normals = {{1, 0, 0}, {1, 0, 0}, {1, 0, 0}};
    int mesh = b.addMesh("Bark", {b.primitive(d)});
    const double s = std::sqrt(0.5);
    int child = b.addNode({{"mesh", mesh}, {"rotation", {0.0, s, 0.0, s}}, {"scale", {2.0, 2.0, 2.0}}});
    int parent = b.addNode({{"translation", {10.0, 0.0, 0.0}}, {"children", {child}}});
    b.setScene({parent});

    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    ASSERT_EQ(model->barkVertices.size(), 3u);
    expectNear(model->barkVertices[0].position, {10, 0, 0});
    expectNear(model->barkVertices[1].position, {10, 0, -2});
    expectNear(model->barkVertices[2].position, {10, 2, 0});
    expectNear(model->barkVertices[0].normal, {0, 0, -1});
}

TEST(GltfImporter, NormalsUseTheInverseTransposeOfAMatrixNode)
{
    // Plane x + y = 1 with normal (1,1,0)/sqrt2; scaling y by 2 gives x + y/2 = 1, whose
    // normal is (1, 0.5, 0) normalised, not the scaled vector (1, 2, 0).
    GltfBuilder b;
    PrimitiveData d;
    d.material = b.addMaterial("Bark", "OPAQUE");
    d.positions = {{1, 0, 0}, {0, 1, 0}, {1, 0, 1}};
    const glm::vec3 n = glm::normalize(glm::vec3(1, 1, 0));
    d.normals = {n, n, n};
    int mesh = b.addMesh("Bark", {b.primitive(d)});
    b.setScene({b.addNode({{"mesh", mesh}, {"matrix", {1, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}})});

    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    expectNear(model->barkVertices[1].position, {0, 2, 0});
    expectNear(model->barkVertices[0].normal, glm::normalize(glm::vec3(1, 0.5f, 0)));
}

TEST(GltfImporter, MirroringNodeKeepsComputedNormalsOnTheFrontSide)
{
    // A counter-clockwise triangle seen from +Z. Mirrored in X it stays in the XY plane and,
    // with the winding flipped as glTF requires, still faces +Z.
    GltfBuilder b;
    int mesh = b.addMesh("Bark", {b.primitive(barkTriangle(b.addMaterial("Bark", "OPAQUE")))});
    b.setScene({b.addNode({{"mesh", mesh}, {"scale", {-1.0, 1.0, 1.0}}})});

    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    expectNear(model->barkVertices[0].normal, {0, 0, 1});
}

TEST(GltfImporter, IndexWidthsOf8And16And32BitsGiveTheSameModel)
{
    std::vector<TreeModel> models;
    for (int bits : {8, 16, 32})
    {
        GltfBuilder b;
        PrimitiveData d;
        d.material = b.addMaterial("Leaf", "MASK");
        d.add(unitQuad({0, 0, 0}));
        d.add(unitQuad({2, 0, 0}));
        d.indexBits = bits;
        b.addMeshNode("Leaves", d);
        EXPECT_EQ(b.json()["accessors"].back()["componentType"], bits == 8 ? 5121 : bits == 16 ? 5123 : 5125);
        auto model = importBuilt(b);
        ASSERT_TRUE(model) << bits << ": " << model.error().message();
        models.push_back(*model);
    }
    for (const TreeModel& m : models)
    {
        EXPECT_EQ(m.leaves.size(), 2u);
        EXPECT_EQ(m.leafIndices, models[0].leafIndices);
    }
}

TEST(GltfImporter, InterleavedStridedAccessorsAndNormalizedUvsAreRead)
{
    // One bufferView holding position (12 bytes) + UV as normalized uint16 (4 bytes) per vertex.
    GltfBuilder b;
    int material = b.addMaterial("Bark", "OPAQUE");
    struct V
    {
        float p[3];
        std::uint16_t uv[2];
    };
    std::vector<V> v = {{{0, 0, 0}, {0, 0}}, {{1, 0, 0}, {65535, 0}}, {{0, 1, 0}, {0, 32768}}};
    int bv = b.addBufferView(v.data(), v.size() * sizeof(V), sizeof(V));
    int pos = b.addAccessor(bv, 5126, 3, "VEC3");
    int uv = b.addAccessor(bv, 5123, 3, "VEC2", 12, true);
    nlohmann::json prim = {{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv}}}, {"material", material}};
    b.setScene({b.addNode({{"mesh", b.addMesh("Bark", {prim})}})});

    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    ASSERT_EQ(model->barkVertices.size(), 3u);
    expectNear(model->barkVertices[2].position, {0, 1, 0});
    EXPECT_NEAR(model->barkVertices[1].uv.x, 1.0f, 1e-6f);
    EXPECT_NEAR(model->barkVertices[2].uv.y, 32768.0f / 65535.0f, 1e-6f);
    EXPECT_EQ(model->barkTriangleCount(), 1u); // non-indexed: vertices 0, 1, 2
}

TEST(GltfImporter, MissingNormalsAreComputedAndMissingUvsAreZero)
{
    GltfBuilder b;
    b.addMeshNode("Bark", barkTriangle(b.addMaterial("Bark", "OPAQUE")));
    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    for (const Vertex& v : model->barkVertices)
    {
        expectNear(v.normal, {0, 0, 1}); // (1,0,0) x (0,1,0)
        EXPECT_EQ(v.uv, glm::vec2(0.0f));
    }
}

TEST(GltfImporter, TriangleStripsAndFansAreConverted)
{
    GltfBuilder b;
    int material = b.addMaterial("Bark", "OPAQUE");
    PrimitiveData strip;
    strip.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    strip.material = material;
    strip.mode = 5;
    PrimitiveData fan = strip;
    fan.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}; // around vertex 0
    fan.mode = 6;
    b.setScene({b.addNode({{"mesh", b.addMesh("Bark", {b.primitive(strip), b.primitive(fan)})}})});

    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    // 4 strip vertices -> 2 triangles, 4 fan vertices -> 2 triangles; all keep facing +Z.
    ASSERT_EQ(model->barkTriangleCount(), 4u);
    for (std::size_t t = 0; t < 4; ++t)
    {
        const glm::vec3& a = model->barkVertices[model->barkIndices[3 * t]].position;
        const glm::vec3& b2 = model->barkVertices[model->barkIndices[3 * t + 1]].position;
        const glm::vec3& c = model->barkVertices[model->barkIndices[3 * t + 2]].position;
        EXPECT_GT(glm::cross(b2 - a, c - a).z, 0.0f) << "triangle " << t;
    }
}

TEST(GltfImporter, MeshUsedByTwoNodesGivesTwoCopies)
{
    GltfBuilder b;
    PrimitiveData d;
    d.material = b.addMaterial("Leaf", "MASK");
    d.add(unitQuad({0, 0, 0}));
    int mesh = b.addMesh("Leaves", {b.primitive(d)});
    int n0 = b.addNode({{"mesh", mesh}});
    int n1 = b.addNode({{"mesh", mesh}, {"translation", {0.0, 0.0, 3.0}}});
    b.setScene({n0, n1});

    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    ASSERT_EQ(model->leaves.size(), 2u);
    EXPECT_NEAR(model->leaves[1].centre.z, 3.0f, 1e-6f);
}

TEST(GltfImporter, DefaultSceneIsTheOneRead)
{
    GltfBuilder b;
    int leafMaterial = b.addMaterial("Leaf", "MASK");
    PrimitiveData one, two;
    one.material = two.material = leafMaterial;
    one.add(unitQuad({0, 0, 0}));
    two.add(unitQuad({0, 0, 0}));
    two.add(unitQuad({5, 0, 0}));
    int n0 = b.addNode({{"mesh", b.addMesh("One", {b.primitive(one)})}});
    int n1 = b.addNode({{"mesh", b.addMesh("Two", {b.primitive(two)})}});
    b.json()["scenes"] = nlohmann::json::array({{{"nodes", {n0}}}, {{"nodes", {n1}}}});
    b.json()["scene"] = 1;

    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    EXPECT_EQ(model->leaves.size(), 2u); // scene 1 has the two-quad mesh
}

// ---- materials, extras, user rule --------------------------------------------------------

TEST(GltfImporter, LeafMaterialOptionOverridesAlphaMode)
{
    GltfBuilder b;
    PrimitiveData leaves, other;
    leaves.material = b.addMaterial("Foliage", "OPAQUE");
    other.material = b.addMaterial("Cutout", "MASK");
    leaves.add(unitQuad({0, 0, 0}));
    other.add(unitQuad({5, 0, 0}));
    b.addMeshNode("A", leaves);
    b.addMeshNode("B", other);

    auto byAlpha = importBuilt(b);
    ASSERT_TRUE(byAlpha) << byAlpha.error().message();
    EXPECT_EQ(byAlpha->leaves.size(), 1u); // only the MASK material
    EXPECT_EQ(byAlpha->barkTriangleCount(), 2u);

    ImportOptions options;
    options.leafMaterials = {"Foliage"};
    auto byName = importBuilt(b, nullptr, options);
    ASSERT_TRUE(byName) << byName.error().message();
    ASSERT_EQ(byName->leaves.size(), 1u); // the rule replaces alphaMode: Foliage yes, Cutout no
    EXPECT_EQ(byName->materials[byName->leaves[0].material].name, "Foliage");
    EXPECT_EQ(byName->barkTriangleCount(), 2u);
}

TEST(GltfImporter, MaterialPropertiesAndBackColourAreRead)
{
    GltfBuilder b;
    int m = b.addMaterial("Leaf", "MASK", -1, {{"treelodBackColour", {0.1, 0.2, 0.3}}});
    b.json()["materials"][std::size_t(m)]["alphaCutoff"] = 0.25;
    b.json()["materials"][std::size_t(m)]["doubleSided"] = true;
    b.json()["materials"][std::size_t(m)]["pbrMetallicRoughness"]["baseColorFactor"] = {0.5, 0.6, 0.7, 1.0};
    PrimitiveData d;
    d.material = m;
    d.add(unitQuad({0, 0, 0}));
    b.addMeshNode("Leaves", d);

    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    const Material& mat = model->materials[0];
    EXPECT_TRUE(mat.isLeaf);
    EXPECT_TRUE(mat.doubleSided);
    EXPECT_FLOAT_EQ(mat.alphaCutoff, 0.25f);
    EXPECT_EQ(mat.baseColour, glm::vec4(0.5f, 0.6f, 0.7f, 1.0f));
    expectNear(mat.backColour, {0.1f, 0.2f, 0.3f});
    EXPECT_EQ(mat.texture, -1);
}

TEST(GltfImporter, SkeletonFromMeshExtrasIsTransformedByItsNode)
{
    GltfBuilder b;
    nlohmann::json skeleton = {{"treelodSkeleton",
                                {{"positions", {0, 0, 0, 0, 1, 0, 0.5, 1.5, 0}},
                                 {"radii", {0.2, 0.1, 0.05}},
                                 {"parents", {-1, 0, 1}}}}};
    int mesh = b.addMesh("Bark", {b.primitive(barkTriangle(b.addMaterial("Bark", "OPAQUE")))}, skeleton);
    b.setScene({b.addNode({{"mesh", mesh}, {"translation", {0.0, 0.0, 5.0}}, {"scale", {2.0, 2.0, 2.0}}})});

    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    ASSERT_EQ(model->skeleton.size(), 3u);
    expectNear(model->skeleton[1].position, {0, 2, 5});
    EXPECT_NEAR(model->skeleton[0].radius, 0.4f, 1e-6f); // uniform scale 2
    EXPECT_EQ(model->skeleton[0].parent, -1);
    EXPECT_EQ(model->skeleton[2].parent, 1);
}

TEST(GltfImporter, SkeletonWithAChildBeforeItsParentIsAnError)
{
    GltfBuilder b;
    nlohmann::json skeleton = {{"treelodSkeleton",
                                {{"positions", {0, 0, 0, 0, 1, 0}}, {"radii", {0.2, 0.1}}, {"parents", {1, -1}}}}};
    int mesh = b.addMesh("Bark", {b.primitive(barkTriangle(b.addMaterial("Bark", "OPAQUE")))}, skeleton);
    b.setScene({b.addNode({{"mesh", mesh}})});

    auto model = importBuilt(b);
    ASSERT_FALSE(model);
    EXPECT_EQ(model.error().element, "mesh 0 'Bark' extras treelodSkeleton node 0");
    EXPECT_TRUE(contains(model.error().reason, "earlier node")) << model.error().reason;
}

TEST(GltfImporter, BareTrunkIsAValidTree)
{
    GltfBuilder b;
    b.addMeshNode("Bark", barkTriangle(b.addMaterial("Bark", "OPAQUE")));
    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    EXPECT_TRUE(model->leaves.empty());
    EXPECT_EQ(model->barkTriangleCount(), 1u);
}

TEST(GltfImporter, LeavesWithoutBarkAreAValidTree)
{
    GltfBuilder b;
    PrimitiveData d;
    d.material = b.addMaterial("Leaf", "MASK");
    d.add(unitQuad({0, 0, 0}));
    b.addMeshNode("Leaves", d);
    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    EXPECT_EQ(model->leaves.size(), 1u);
    EXPECT_EQ(model->barkTriangleCount(), 0u);
}

TEST(GltfImporter, PrimitiveWithoutMaterialIsBarkWithADefaultMaterial)
{
    GltfBuilder b;
    b.addMeshNode("Bark", barkTriangle(-1));
    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    ASSERT_EQ(model->materials.size(), 1u);
    EXPECT_EQ(model->materials[0].name, "(default)");
    EXPECT_FALSE(model->materials[0].isLeaf);
}

// ---- images ------------------------------------------------------------------------------

namespace
{
    const std::vector<std::uint8_t> kTwoPixels = {255, 0, 0, 255, 0, 128, 255, 64}; // 2x1 RGBA

    /// Two leaf materials sharing one texture, and a quad for each.
    void addTexturedLeaves(GltfBuilder& b, int image)
    {
        int texture = b.addTexture(image);
        PrimitiveData d;
        d.material = b.addMaterial("LeafA", "MASK", texture);
        d.add(unitQuad({0, 0, 0}));
        PrimitiveData e;
        e.material = b.addMaterial("LeafB", "MASK", texture);
        e.add(unitQuad({3, 0, 0}));
        b.setScene({b.addNode({{"mesh", b.addMesh("Leaves", {b.primitive(d), b.primitive(e)})}})});
    }

    void expectTwoPixels(const TreeModel& model)
    {
        ASSERT_EQ(model.textures.size(), 1u); // deduplicated per glTF image
        const TextureImage& t = model.textures[0];
        EXPECT_EQ(t.width, 2);
        EXPECT_EQ(t.height, 1);
        EXPECT_EQ(t.rgba, kTwoPixels); // straight alpha, values untouched
        EXPECT_EQ(model.materials[0].texture, 0);
        EXPECT_EQ(model.materials[1].texture, 0);
    }
}

TEST(GltfImporter, EmbeddedGlbImageIsDecodedOncePerImage)
{
    GltfBuilder b;
    addTexturedLeaves(b, b.addImageEmbedded(makeRgbaPng(2, 1, kTwoPixels)));
    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    expectTwoPixels(*model);
    EXPECT_EQ(model->textures[0].name, "image 0");
}

TEST(GltfImporter, DataUriImageIsDecoded)
{
    GltfBuilder b;
    addTexturedLeaves(b, b.addImageUri("data:image/png;base64," + base64(makeRgbaPng(2, 1, kTwoPixels))));
    auto model = importText(b.gltfWithDataUri());
    ASSERT_TRUE(model) << model.error().message();
    expectTwoPixels(*model);
}

TEST(GltfImporter, ExternalImageBesideTheGltfIsDecoded)
{
    const std::string dir = testDir("external-image");
    ASSERT_TRUE(writeBytes(dir + "/leaf.png", makeRgbaPng(2, 1, kTwoPixels)));
    GltfBuilder b;
    addTexturedLeaves(b, b.addImageUri("leaf.png"));
    ASSERT_TRUE(b.writeGltf(dir + "/tree.gltf"));

    auto model = importGltf(dir + "/tree.gltf");
    ASSERT_TRUE(model) << model.error().message();
    expectTwoPixels(*model);
    EXPECT_EQ(model->textures[0].name, "leaf.png");
    EXPECT_EQ(model->name, "tree");
}

TEST(GltfImporter, PalettePngKeepsItsTrnsAlpha)
{
    // 4x1 palette image, 8-bit indices 0..3; tRNS gives alpha 0, 128, 255 to entries 0..2
    // and entry 3 has none, so it is opaque (PNG spec 11.3.2.1).
    const std::vector<std::uint8_t> plte = {255, 0, 0, 0, 255, 0, 0, 0, 255, 10, 20, 30};
    const std::vector<std::uint8_t> trns = {0, 128, 255};
    GltfBuilder b;
    addTexturedLeaves(b, b.addImageEmbedded(makePng(4, 1, 3, 8, {0, 1, 2, 3}, plte, trns)));
    auto model = importBuilt(b);
    ASSERT_TRUE(model) << model.error().message();
    ASSERT_EQ(model->textures.size(), 1u);
    const std::vector<std::uint8_t> expected = {255, 0, 0, 0, 0, 255, 0, 128, 0, 0, 255, 255, 10, 20, 30, 255};
    EXPECT_EQ(model->textures[0].rgba, expected);
}

TEST(GltfImporter, MissingExternalImageIsAnErrorNamingImageAndPath)
{
    const std::string dir = testDir("missing-image");
    GltfBuilder b;
    int image = b.addImageUri("missing.png");
    b.json()["images"][std::size_t(image)]["name"] = "leafImage";
    addTexturedLeaves(b, image);
    ASSERT_TRUE(b.writeGltf(dir + "/tree.gltf"));

    auto model = importGltf(dir + "/tree.gltf");
    ASSERT_FALSE(model);
    EXPECT_EQ(model.error().file, dir + "/tree.gltf");
    EXPECT_EQ(model.error().element, "image 0 'leafImage'");
    EXPECT_TRUE(contains(model.error().reason, dir + "/missing.png")) << model.error().reason;
    EXPECT_TRUE(contains(model.error().reason, "does not exist")) << model.error().reason;
}

TEST(GltfImporter, ImageThatIsNotPngOrJpegIsAnError)
{
    GltfBuilder b;
    addTexturedLeaves(b, b.addImageEmbedded({'G', 'I', 'F', '8', '9', 'a', 0, 0}));
    auto model = importBuilt(b);
    ASSERT_FALSE(model);
    EXPECT_EQ(model.error().element, "image 0 ''");
    EXPECT_TRUE(contains(model.error().reason, "not PNG or JPEG")) << model.error().reason;
}

// ---- bad input -----------------------------------------------------------------------------

TEST(GltfImporter, MissingFileIsAnErrorNamingTheFile)
{
    const std::string path = testDir("missing-file") + "/nothing.glb";
    auto model = importGltf(path);
    ASSERT_FALSE(model);
    EXPECT_EQ(model.error().file, path);
    EXPECT_EQ(model.error().reason, "file does not exist");
}

TEST(GltfImporter, RandomBytesAreNotGltf)
{
    std::vector<std::uint8_t> bytes(256);
    std::uint32_t x = 12345;
    for (std::uint8_t& c : bytes)
    {
        x = x * 1664525u + 1013904223u;
        c = std::uint8_t(x >> 24);
    }
    bytes[0] = 0x17; // neither 'g' (glb magic) nor '{' (JSON)
    const std::string path = testDir("random-bytes") + "/noise.glb";
    ASSERT_TRUE(writeBytes(path, bytes));
    auto model = importGltf(path);
    ASSERT_FALSE(model);
    EXPECT_EQ(model.error().file, path);
    EXPECT_TRUE(contains(model.error().reason, "not glTF")) << model.error().message();
}

TEST(GltfImporter, JsonThatIsNotGltfIsAnError)
{
    auto model = importText("{\"hello\": [1, 2, 3]}");
    ASSERT_FALSE(model);
    EXPECT_EQ(model.error().file, "test.gltf");
    EXPECT_TRUE(contains(model.error().reason, "not valid glTF")) << model.error().message();
}

TEST(GltfImporter, TruncatedGlbIsAnError)
{
    GltfBuilder b;
    PrimitiveData d;
    d.material = b.addMaterial("Leaf", "MASK");
    d.add(unitQuad({0, 0, 0}));
    b.addMeshNode("Leaves", d);
    std::vector<std::uint8_t> bytes = b.glb();
    const std::size_t full = bytes.size();
    bytes.resize(full / 2);
    const std::string path = testDir("truncated") + "/half.glb";
    ASSERT_TRUE(writeBytes(path, bytes));

    auto model = importGltf(path);
    ASSERT_FALSE(model);
    EXPECT_EQ(model.error().file, path);
    EXPECT_EQ(model.error().element, "glb header");
    EXPECT_EQ(model.error().reason, "truncated .glb: the header says " + std::to_string(full) +
                                        " bytes, the data has " + std::to_string(full / 2));

    bytes.resize(7); // not even a header
    auto tiny = importGltfFromMemory(bytes.data(), bytes.size(), "tiny.glb", "");
    ASSERT_FALSE(tiny);
    EXPECT_TRUE(contains(tiny.error().reason, "truncated .glb")) << tiny.error().message();
}

TEST(GltfImporter, GlbWithATruncatedBinChunkIsAnError)
{
    GltfBuilder b;
    b.addMeshNode("Bark", barkTriangle(b.addMaterial("Bark", "OPAQUE")));
    std::vector<std::uint8_t> bytes = b.glb();
    // Shorten the file and its header length by 8 bytes: the BIN chunk now claims more.
    bytes.resize(bytes.size() - 8);
    std::uint32_t length = std::uint32_t(bytes.size());
    std::memcpy(&bytes[8], &length, 4);
    auto model = importGltfFromMemory(bytes.data(), bytes.size(), "short.glb", "");
    ASSERT_FALSE(model);
    EXPECT_EQ(model.error().element, "glb chunk 1 (BIN)");
    EXPECT_TRUE(contains(model.error().reason, "truncated")) << model.error().message();
}

TEST(GltfImporter, IndexOutOfRangeNamesMeshPrimitiveAndAccessor)
{
    GltfBuilder b;
    b.addMeshNode("Bark", barkTriangle(b.addMaterial("Bark", "OPAQUE")));
    PrimitiveData d;
    d.material = b.addMaterial("Leaf", "MASK");
    d.add(unitQuad({0, 0, 0}));
    d.indices[4] = 4711;
    b.addMeshNode("Leaves", d);
    const int indexAccessor = int(b.json()["accessors"].size()) - 1;

    auto model = importBuilt(b);
    ASSERT_FALSE(model);
    EXPECT_EQ(model.error().file, "test.glb");
    EXPECT_EQ(model.error().element, "mesh 1 'Leaves' primitive 0 accessor " + std::to_string(indexAccessor) + " (indices)");
    EXPECT_EQ(model.error().reason, "index 4711 out of range (4 vertices)");
}

TEST(GltfImporter, AccessorOverrunningItsBufferViewIsAnError)
{
    GltfBuilder b;
    b.addMeshNode("Bark", barkTriangle(b.addMaterial("Bark", "OPAQUE")));
    b.json()["accessors"][0]["count"] = 4; // the view holds 3 positions
    auto model = importBuilt(b);
    ASSERT_FALSE(model);
    EXPECT_EQ(model.error().element, "mesh 0 'Bark' primitive 0 accessor 0 (POSITION)");
    EXPECT_TRUE(contains(model.error().reason, "overrun bufferView 0")) << model.error().reason;
}

TEST(GltfImporter, NanOrInfinitePositionIsAnErrorNamingTheAccessor)
{
    for (float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()})
    {
        GltfBuilder b;
        PrimitiveData d;
        d.material = b.addMaterial("Leaf", "MASK");
        d.add(unitQuad({0, 0, 0}));
        d.positions[2].y = bad;
        b.addMeshNode("Leaves", d);
        auto model = importBuilt(b);
        ASSERT_FALSE(model);
        EXPECT_EQ(model.error().element, "mesh 0 'Leaves' primitive 0 accessor 0 (POSITION)");
        EXPECT_TRUE(contains(model.error().reason, "vertex 2 position is not finite")) << model.error().reason;
    }
}

TEST(GltfImporter, MillionMetreTreeImportsWithAWarning)
{
    // Everything scaled by 1e6: still a tree, just big; leaves are not "degenerate".
    GltfBuilder b;
    PrimitiveData trunk = barkTriangle(b.addMaterial("Bark", "OPAQUE"));
    for (glm::vec3& p : trunk.positions)
        p *= 1e6f;
    b.addMeshNode("Bark", trunk);
    PrimitiveData d;
    d.material = b.addMaterial("Leaf", "MASK");
    d.add(makeQuad({0, 9e5f, 0}, {5e4f, 0, 0}, {0, 5e4f, 0}));
    d.add(makeQuad({2e5f, 9e5f, 0}, {5e4f, 0, 0}, {0, 5e4f, 0}));
    b.addMeshNode("Leaves", d);

    ImportReport report;
    auto model = importBuilt(b, &report);
    ASSERT_TRUE(model) << model.error().message();
    EXPECT_EQ(model->leaves.size(), 2u);
    EXPECT_NEAR(model->boundsMax.y, 1e6f, 1.0f);
    bool warned = false;
    for (const std::string& w : report.warnings)
        warned = warned || contains(w, "more than 1 km");
    EXPECT_TRUE(warned);
}

TEST(GltfImporter, FileWithoutTrianglesIsAnError)
{
    GltfBuilder b;
    PrimitiveData points;
    points.positions = {{0, 0, 0}, {1, 0, 0}};
    points.mode = 0;
    b.addMeshNode("Points", points);
    ImportReport report;
    auto model = importBuilt(b, &report);
    ASSERT_FALSE(model);
    EXPECT_EQ(model.error().element, "scene");
    EXPECT_TRUE(contains(model.error().reason, "no triangles")) << model.error().reason;
    EXPECT_EQ(report.skippedPrimitives, 1u);
}

TEST(GltfImporter, NodeCycleIsAnError)
{
    GltfBuilder b;
    int mesh = b.addMesh("Bark", {b.primitive(barkTriangle(b.addMaterial("Bark", "OPAQUE")))});
    b.addNode({{"mesh", mesh}, {"children", {1}}});
    b.addNode({{"children", {0}}});
    b.setScene({0});
    auto model = importBuilt(b);
    ASSERT_FALSE(model);
    EXPECT_EQ(model.error().element, "node 0");
    EXPECT_TRUE(contains(model.error().reason, "appears twice")) << model.error().reason;
}

TEST(GltfImporter, InMemoryDataWithoutBaseDirReadsNoFile)
{
    const std::string dir = testDir("no-base-dir");
    GltfBuilder b;
    b.addMeshNode("Bark", barkTriangle(b.addMaterial("Bark", "OPAQUE")));
    ASSERT_TRUE(b.writeGltf(dir + "/tree.gltf"));
    const std::string text = b.gltfWithExternalBin("tree.bin");

    auto without = importText(text, "");
    ASSERT_FALSE(without);
    EXPECT_TRUE(contains(without.error().reason, "tree.bin")) << without.error().message();

    auto with = importText(text, dir);
    ASSERT_TRUE(with) << with.error().message();
    EXPECT_EQ(with->barkTriangleCount(), 1u);
}

TEST(GltfImporter, UnsupportedRequiredExtensionIsAnError)
{
    GltfBuilder b;
    b.addMeshNode("Bark", barkTriangle(b.addMaterial("Bark", "OPAQUE")));
    b.json()["extensionsUsed"] = {"KHR_draco_mesh_compression"};
    b.json()["extensionsRequired"] = {"KHR_draco_mesh_compression"};
    auto model = importBuilt(b);
    ASSERT_FALSE(model);
    EXPECT_TRUE(contains(model.error().reason, "KHR_draco_mesh_compression")) << model.error().message();
}

TEST(GltfImporter, ProgressReachesTheEndOfEachStep)
{
    GltfBuilder b;
    PrimitiveData d;
    d.material = b.addMaterial("Leaf", "MASK");
    d.add(unitQuad({0, 0, 0}));
    b.addMeshNode("Leaves", d);
    std::map<std::string, float> last;
    ImportOptions options;
    options.progress = [&](const std::string& step, float f) { last[step] = f; };
    auto model = importBuilt(b, nullptr, options);
    ASSERT_TRUE(model) << model.error().message();
    for (const char* step : {"read", "meshes", "leaves"})
        EXPECT_EQ(last[step], 1.0f) << step;
}

// ---- round trip with the generator and the exporter ------------------------------------------

TEST(GltfImporter, GeneratedTreeRoundTripsThroughGlb)
{
    // Every generated leaf is a quad with 4 own vertices and no shared position, so import
    // must find exactly the generator's leaves, vertices and triangles again.
    GeneratorOptions options;
    options.preset = TreePreset::Birch;
    options.leafCount = 300;
    options.textureSize = 16;
    auto tree = generateTree(options);
    ASSERT_TRUE(tree) << tree.error().message();
    auto glb = encodeGlb(*tree);
    ASSERT_TRUE(glb) << glb.error().message();

    ImportReport report;
    auto model = importGltfFromMemory(glb->data(), glb->size(), "birch.glb", "", {}, &report);
    ASSERT_TRUE(model) << model.error().message();
    EXPECT_EQ(model->leaves.size(), tree->leaves.size());
    EXPECT_EQ(model->leafVertices.size(), tree->leafVertices.size());
    EXPECT_EQ(model->leafTriangleCount(), tree->leafTriangleCount());
    EXPECT_EQ(model->barkTriangleCount(), tree->barkTriangleCount());
    EXPECT_EQ(model->barkVertices.size(), tree->barkVertices.size());
    EXPECT_EQ(model->skeleton.size(), tree->skeleton.size());
    EXPECT_EQ(model->textures.size(), tree->textures.size());
    EXPECT_EQ(report.droppedDegenerateLeaves, 0u);
    EXPECT_EQ(report.duplicateLeaves, 0u);
}

TEST(GltfImporter, TruncatedPngIsAnErrorNamingTheImage)
{
    std::vector<std::uint8_t> png = makeRgbaPng(2, 1, kTwoPixels);
    png.resize(png.size() - 20); // cut inside IDAT: IEND is gone
    GltfBuilder b;
    addTexturedLeaves(b, b.addImageEmbedded(png));
    auto model = importBuilt(b);
    ASSERT_FALSE(model);
    EXPECT_EQ(model.error().element, "image 0 ''");
    EXPECT_TRUE(contains(model.error().reason, "truncated PNG")) << model.error().reason;
}

// ---- hostile sizes: claims refused before anything of their size is allocated ------------

namespace
{
    /// Largest single allocation allowed while importing a hostile file of under 1 KiB.
    constexpr std::size_t kHostileAllocationBound = std::size_t(1) << 20;

    /// Imports with the allocation tracker on; `largest` gets the largest single allocation.
    template <typename Import> Result<TreeModel> importTracked(Import import, std::size_t& largest)
    {
        Result<TreeModel> model = TreeModel();
        test::AllocationTracker tracker;
        model = import();
        largest = tracker.largest();
        return model;
    }
}

TEST(GltfImporter, ImageHeaderClaimingAHugeSizeIsRefusedBeforeDecoding)
{
    // A few bytes whose PNG IHDR or JPEG frame header claims a huge image (65536 x 65536 RGBA8
    // would be 16 GiB; a JPEG says at most 65535), embedded in a .glb and as a file beside a
    // .gltf: refused from the header with the image and the limit. Nothing near the claimed size
    // is allocated: the largest single allocation stays under 1 MiB.
    const std::vector<std::uint8_t> png = makeRgbaPng(2, 1, kTwoPixels);
    struct Case
    {
        std::string extension;
        std::vector<std::uint8_t> bytes;
        std::string claim;
    };
    const std::vector<Case> cases = {
        {"png", withPngSize(png, 65536, 65536), "PNG header declares 65536x65536 pixels"},
        {"png", withPngSize(png, 0x7fffffff, 1), "PNG header declares 2147483647x1 pixels"},
        {"png", withPngSize(png, 16385, 1), "PNG header declares 16385x1 pixels"},
        {"png", withPngSize(png, 1, 16385), "PNG header declares 1x16385 pixels"},
        {"png", withPngSize(png, 8193, 8193), "PNG header declares 8193x8193 pixels"}, // > 64 Mpixel
        {"jpg", makeJpegHeader(65535, 65535, false), "JPEG header declares 65535x65535 pixels"},
        {"jpg", makeJpegHeader(65500, 65500, true), "JPEG header declares 65500x65500 pixels"},
        {"jpg", makeJpegHeader(16384, 4097, true), "JPEG header declares 16384x4097 pixels"},
    };
    const std::string limit = ", larger than the limit (16384 per side, 64 Mpixel); not decoded";
    for (const Case& c : cases)
    {
        GltfBuilder embedded;
        const int image = embedded.addImageEmbedded(c.bytes);
        embedded.json()["images"][std::size_t(image)]["name"] = "huge";
        addTexturedLeaves(embedded, image);
        std::size_t largest = 0;
        auto model = importTracked([&] { return importBuilt(embedded); }, largest);
        ASSERT_FALSE(model) << c.claim;
        EXPECT_EQ(model.error().file, "test.glb");
        EXPECT_EQ(model.error().element, "image 0 'huge'");
        EXPECT_EQ(model.error().reason, c.claim + limit);
        if (test::AllocationTracker::available())
        {
            EXPECT_LT(largest, kHostileAllocationBound) << c.claim;
        }

        const std::string dir = testDir("huge-image");
        ASSERT_TRUE(writeBytes(dir + "/huge." + c.extension, c.bytes));
        GltfBuilder external;
        addTexturedLeaves(external, external.addImageUri("huge." + c.extension));
        ASSERT_TRUE(external.writeGltf(dir + "/tree.gltf"));
        model = importTracked([&] { return importGltf(dir + "/tree.gltf"); }, largest);
        ASSERT_FALSE(model) << c.claim;
        EXPECT_EQ(model.error().file, dir + "/tree.gltf");
        EXPECT_EQ(model.error().element, "image 0 ''");
        EXPECT_EQ(model.error().reason, c.claim + limit);
        if (test::AllocationTracker::available())
        {
            EXPECT_LT(largest, kHostileAllocationBound) << c.claim;
        }
    }

    // At the limit of a side the header passes; what follows is the decoder's business (these
    // bytes hold no such image, so it may fail, but not on the size).
    for (const auto& atLimit : {withPngSize(png, 16384, 1), withPngSize(png, 1, 16384),
                                makeJpegHeader(16384, 1, false), makeJpegHeader(1, 16384, true)})
    {
        GltfBuilder b;
        addTexturedLeaves(b, b.addImageEmbedded(atLimit));
        auto model = importBuilt(b);
        if (!model)
        {
            EXPECT_FALSE(contains(model.error().reason, "header declares")) << model.error().message();
        }
    }
}

TEST(GltfImporter, TenMillionClaimedVerticesOverAFewBytesAreRefusedAtTheAccessor)
{
    // A leaf quad whose accessors in turn claim 10 000 000 elements over views of 24 to 48 bytes:
    // refused at the accessor with the claim and the view's size, before anything proportional to
    // the claim is allocated (10 M vertices would take 320 MB): the largest single allocation
    // stays under 1 MiB.
    auto quad = [](GltfBuilder& b) {
        PrimitiveData d;
        d.material = b.addMaterial("Leaf", "MASK");
        d.add(unitQuad({0, 0, 0}));
        d.normals.assign(4, glm::vec3(0, 0, 1));
        b.addMeshNode("Leaves", d);
    };
    struct Case
    {
        int accessor; ///< GltfBuilder::primitive writes POSITION, NORMAL, TEXCOORD_0, indices
        std::string role;
        std::string overrun;
    };
    const std::vector<Case> cases = {
        {0, "POSITION", "10000000 elements of 12 bytes (stride 12) at offset 0 overrun bufferView 0 (48 bytes)"},
        {1, "NORMAL", "10000000 elements of 12 bytes (stride 12) at offset 0 overrun bufferView 1 (48 bytes)"},
        {2, "TEXCOORD_0", "10000000 elements of 8 bytes (stride 8) at offset 0 overrun bufferView 2 (32 bytes)"},
        {3, "indices", "10000000 elements of 4 bytes (stride 4) at offset 0 overrun bufferView 3 (24 bytes)"},
    };
    for (const Case& c : cases)
    {
        GltfBuilder b;
        quad(b);
        ASSERT_TRUE(importBuilt(b)) << "the quad itself imports";
        b.json()["accessors"][std::size_t(c.accessor)]["count"] = 10000000;
        std::size_t largest = 0;
        auto model = importTracked([&] { return importBuilt(b); }, largest);
        ASSERT_FALSE(model) << c.role;
        EXPECT_EQ(model.error().file, "test.glb");
        EXPECT_EQ(model.error().element,
                  "mesh 0 'Leaves' primitive 0 accessor " + std::to_string(c.accessor) + " (" + c.role + ")");
        EXPECT_EQ(model.error().reason, c.overrun);
        if (test::AllocationTracker::available())
        {
            EXPECT_LT(largest, kHostileAllocationBound) << c.role;
        }
    }

    // The view claims 120 MB too, so the 10 M positions fit it; the buffer holds 152 bytes.
    GltfBuilder b;
    quad(b);
    const std::size_t bufferBytes = b.bin().size();
    b.json()["accessors"][0]["count"] = 10000000;
    b.json()["bufferViews"][0]["byteLength"] = 120000000;
    std::size_t largest = 0;
    auto model = importTracked([&] { return importBuilt(b); }, largest);
    ASSERT_FALSE(model);
    EXPECT_EQ(model.error().element, "mesh 0 'Leaves' primitive 0 accessor 0 (POSITION) bufferView 0");
    EXPECT_EQ(model.error().reason,
              "byte range 0 + 120000000 exceeds buffer 0 (" + std::to_string(bufferBytes) + " bytes)");
    if (test::AllocationTracker::available())
    {
        EXPECT_LT(largest, kHostileAllocationBound);
    }
}
