// treelod generate: the procedural generator, its textures and the .glb writer.
#include "TreeLod/GltfExporter.h"
#include "TreeLod/GltfImporter.h"
#include "TreeLod/LeafTexture.h"
#include "TreeLod/TreeGenerator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

using namespace TreeLod;

namespace
{
    const TreePreset kPresets[] = {TreePreset::Oak, TreePreset::Conifer, TreePreset::Birch, TreePreset::Shrub};

    TreeModel generate(TreePreset preset, std::uint32_t seed, std::uint32_t leaves, int textureSize = 32)
    {
        GeneratorOptions options;
        options.preset = preset;
        options.seed = seed;
        options.leafCount = leaves;
        options.textureSize = textureSize;
        Result<TreeModel> model = generateTree(options);
        EXPECT_TRUE(model.ok()) << (model.ok() ? "" : model.error().message());
        return model.ok() ? std::move(model).value() : TreeModel();
    }

    bool sameVertices(const std::vector<Vertex>& a, const std::vector<Vertex>& b)
    {
        return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(Vertex)) == 0);
    }

    std::filesystem::path testOut(const std::string& name)
    {
        const char* dir = std::getenv("TREELOD_TEST_OUT");
        std::filesystem::path root = dir ? dir : std::filesystem::temp_directory_path() / "treelod-test-out";
        std::filesystem::create_directories(root);
        return root / name;
    }
}

// The generator draws every random number from a seeded mt19937 through our own mapping,
// so a second run with the same options must reproduce each vertex bit for bit.
TEST(TreeGenerator, sameSeedGivesIdenticalModel)
{
    TreeModel a = generate(TreePreset::Oak, 7, 500);
    TreeModel b = generate(TreePreset::Oak, 7, 500);
    EXPECT_TRUE(sameVertices(a.barkVertices, b.barkVertices));
    EXPECT_TRUE(sameVertices(a.leafVertices, b.leafVertices));
    EXPECT_EQ(a.barkIndices, b.barkIndices);
    EXPECT_EQ(a.leafIndices, b.leafIndices);
    EXPECT_EQ(a.textures[1].rgba, b.textures[1].rgba);
}

// The seed feeds every branching decision, so another seed must move the branches.
TEST(TreeGenerator, differentSeedGivesDifferentModel)
{
    TreeModel a = generate(TreePreset::Oak, 7, 500);
    TreeModel b = generate(TreePreset::Oak, 8, 500);
    EXPECT_FALSE(sameVertices(a.barkVertices, b.barkVertices));
    EXPECT_FALSE(sameVertices(a.leafVertices, b.leafVertices));
}

// Branches come from their own random stream, so changing only the leaf count must keep
// the bark exactly (a user can trade leaves for speed without getting another tree).
TEST(TreeGenerator, leafCountDoesNotChangeBranches)
{
    TreeModel a = generate(TreePreset::Birch, 3, 200);
    TreeModel b = generate(TreePreset::Birch, 3, 2000);
    EXPECT_TRUE(sameVertices(a.barkVertices, b.barkVertices));
}

// Leaves are distributed by rounding cumulative weights, which ends exactly at the request
// (1237 is not a round number, so no stem count divides it evenly).
TEST(TreeGenerator, hitsRequestedLeafCountExactly)
{
    for (std::uint32_t count : {100u, 1000u, 1237u})
    {
        TreeModel model = generate(TreePreset::Conifer, 2, count);
        EXPECT_EQ(model.leaves.size(), count);
        EXPECT_EQ(model.leafVertices.size(), 4u * count);
        EXPECT_EQ(model.leafIndices.size(), 6u * count);
    }
}

// The upper limit must be reachable (and, per the brief, quickly: the whole test binary
// stays well under 20 s).
TEST(TreeGenerator, generatesTwoHundredThousandLeaves)
{
    TreeModel model = generate(TreePreset::Oak, 1, 200000);
    EXPECT_EQ(model.leaves.size(), 200000u);
    EXPECT_TRUE(model.validate().ok());
}

// 99 and 200001 are just outside the documented range; the error must name the option.
TEST(TreeGenerator, rejectsLeafCountOutOfRange)
{
    for (std::uint32_t count : {1u, 99u, 200001u})
    {
        GeneratorOptions options;
        options.leafCount = count;
        Result<TreeModel> model = generateTree(options);
        ASSERT_FALSE(model.ok());
        EXPECT_NE(model.error().element.find("--leaves"), std::string::npos);
    }
}

// Texture sizes must be powers of two in 16..4096 (mipmaps), heights positive and sane.
TEST(TreeGenerator, rejectsBadTextureSizeAndHeight)
{
    GeneratorOptions options;
    options.textureSize = 100;
    EXPECT_FALSE(generateTree(options).ok());
    options.textureSize = 64;
    options.height = -3.0f;
    Result<TreeModel> model = generateTree(options);
    ASSERT_FALSE(model.ok());
    EXPECT_NE(model.error().element.find("--height"), std::string::npos);
}

// An atlas of 2 x 2 leaf images: every leaf maps exactly one cell, each image is used, the
// cells hold different leaves; the branches and leaf positions are those of the plain tree.
TEST(TreeGenerator, leafImagesMakeAnAtlasAndEveryLeafMapsOneCell)
{
    GeneratorOptions options;
    options.leafCount = 800;
    options.textureSize = 64;
    const Result<TreeModel> plain = generateTree(options);
    options.leafImages = 4;
    const Result<TreeModel> atlas = generateTree(options);
    ASSERT_TRUE(plain.ok() && atlas.ok());
    EXPECT_TRUE(sameVertices(plain->barkVertices, atlas->barkVertices));
    ASSERT_EQ(atlas->leaves.size(), plain->leaves.size());
    const TextureImage& texture = atlas->textures[std::size_t(atlas->materials[1].texture)];
    ASSERT_EQ(texture.width, 64);
    std::size_t perCell[4] = {0, 0, 0, 0};
    for (std::size_t l = 0; l < atlas->leaves.size(); ++l)
    {
        const Leaf& leaf = atlas->leaves[l];
        const glm::vec2 cell = glm::floor(2.0f * (0.5f * (leaf.uvMin + leaf.uvMax)));
        ASSERT_EQ(leaf.uvMax - leaf.uvMin, glm::vec2(0.5f)) << "leaf " << l;
        ASSERT_EQ(leaf.uvMin, 0.5f * cell) << "leaf " << l;
        ++perCell[std::size_t(cell.x + 2.0f * cell.y)];
        EXPECT_EQ(leaf.centre, plain->leaves[l].centre);
    }
    for (std::size_t c = 0; c < 4; ++c)
        EXPECT_GT(perCell[c], 150u) << "cell " << c;
    // The cells' opaque texel counts differ (oak, birch, shrub and conifer leaves).
    std::size_t opaque[4] = {0, 0, 0, 0};
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x)
            opaque[(x / 32) + 2 * (y / 32)] += texture.rgba[(std::size_t(y) * 64 + std::size_t(x)) * 4 + 3] >= 128;
    for (std::size_t a = 0; a < 4; ++a)
    {
        EXPECT_GT(opaque[a], 50u) << "cell " << a;
        for (std::size_t b = a + 1; b < 4; ++b)
            EXPECT_NE(opaque[a], opaque[b]) << "cells " << a << ", " << b;
    }
}

// Several leaf materials: leaves dealt in turn, each material its own tint and cutoff, and the
// .glb keeps them apart (alpha mode MASK, cutoff, factor).
TEST(TreeGenerator, leafMaterialsDealLeavesAndRoundTrip)
{
    GeneratorOptions options;
    options.leafCount = 600;
    options.textureSize = 32;
    options.leafMaterials = 6;
    const Result<TreeModel> model = generateTree(options);
    ASSERT_TRUE(model.ok()) << model.error().message();
    ASSERT_EQ(model->materials.size(), 7u);
    std::size_t count[7] = {0, 0, 0, 0, 0, 0, 0};
    for (const Leaf& leaf : model->leaves)
        ++count[leaf.material];
    EXPECT_EQ(count[0], 0u);
    for (std::size_t m = 1; m < 7; ++m)
    {
        EXPECT_EQ(count[m], 100u) << model->materials[m].name;
        EXPECT_TRUE(model->materials[m].isLeaf);
        for (std::size_t n = 1; n < m; ++n)
            EXPECT_NE(model->materials[m].baseColour, model->materials[n].baseColour);
    }
    EXPECT_EQ(model->materials[1].name, "Leaves");
    EXPECT_EQ(model->materials[1].alphaCutoff, 0.5f);
    EXPECT_FLOAT_EQ(model->materials[2].alphaCutoff, 0.45f);
    const std::filesystem::path path = testOut("generator-materials.glb");
    ASSERT_TRUE(writeGlb(model.value(), path.string()).ok());
    Result<TreeModel> back = importGltf(path.string());
    ASSERT_TRUE(back.ok()) << back.error().message();
    std::size_t leafMaterials = 0;
    for (const Material& m : back->materials)
        if (m.isLeaf)
        {
            ++leafMaterials;
            const auto same = std::find_if(model->materials.begin(), model->materials.end(),
                                           [&](const Material& o) { return o.name == m.name; });
            ASSERT_NE(same, model->materials.end()) << m.name;
            EXPECT_FLOAT_EQ(m.alphaCutoff, same->alphaCutoff) << m.name;
            EXPECT_EQ(m.baseColour, same->baseColour) << m.name;
        }
    EXPECT_EQ(leafMaterials, 6u);
}

TEST(TreeGenerator, rejectsLeafImagesAndMaterialsOutOfRange)
{
    for (std::uint32_t images : {0u, 5u})
    {
        GeneratorOptions options;
        options.leafImages = images;
        Result<TreeModel> model = generateTree(options);
        ASSERT_FALSE(model.ok());
        EXPECT_EQ(model.error().element, "option --leaf-images");
    }
    for (std::uint32_t materials : {0u, 17u})
    {
        GeneratorOptions options;
        options.leafMaterials = materials;
        Result<TreeModel> model = generateTree(options);
        ASSERT_FALSE(model.ok());
        EXPECT_EQ(model.error().element, "option --leaf-materials");
    }
}

// A folded leaf is one mesh of two quads along its midrib: the same tree otherwise, each wing in
// its own plane raised by the fold, the whole leaf mapped once, one leaf again after a round
// trip through glTF (the importer's leaves are connected meshes).
TEST(TreeGenerator, leafFoldMakesEveryLeafTwoQuadsInOneMesh)
{
    GeneratorOptions flatOptions;
    flatOptions.preset = TreePreset::Birch;
    flatOptions.leafCount = 300;
    flatOptions.textureSize = 32;
    GeneratorOptions foldOptions = flatOptions;
    foldOptions.leafFold = 40.0f;
    Result<TreeModel> flat = generateTree(flatOptions), folded = generateTree(foldOptions);
    ASSERT_TRUE(flat.ok() && folded.ok());
    ASSERT_TRUE(folded->validate()) << folded->validate().error().message();
    ASSERT_EQ(folded->leaves.size(), flat->leaves.size());
    EXPECT_EQ(folded->barkVertices.size(), flat->barkVertices.size());
    for (std::size_t l = 0; l < folded->leaves.size(); ++l)
    {
        const Leaf& leaf = folded->leaves[l];
        ASSERT_EQ(leaf.vertexCount, 6u);
        ASSERT_EQ(leaf.indexCount, 12u);
        EXPECT_EQ(leaf.uvMin, glm::vec2(0.0f));
        EXPECT_EQ(leaf.uvMax, glm::vec2(1.0f));
        // Wings raised by 40 degrees each: the leaf area is the flat one's, its projection on
        // the face cos(40) of it, and the wings' normals 80 degrees apart.
        EXPECT_NEAR(leaf.area, flat->leaves[l].area, 1e-3f * flat->leaves[l].area);
        const auto& v = folded->leafVertices;
        const glm::vec3 leftNormal = v[leaf.firstVertex].normal, rightNormal = v[leaf.firstVertex + 2].normal;
        EXPECT_NEAR(glm::dot(leftNormal, rightNormal), std::cos(glm::radians(80.0f)), 1e-3f) << l;
        EXPECT_GT(glm::dot(leaf.normal, flat->leaves[l].normal), 0.999f) << l;
        for (std::uint32_t t = leaf.firstIndex; t < leaf.firstIndex + leaf.indexCount; t += 3)
        {
            const glm::vec3 a = v[folded->leafIndices[t]].position, b = v[folded->leafIndices[t + 1]].position,
                            c = v[folded->leafIndices[t + 2]].position;
            EXPECT_GT(glm::dot(glm::cross(b - a, c - a), leaf.normal), 0.0f) << "leaf " << l << " faces away";
        }
    }
    const std::filesystem::path path = testOut("generator-folded.glb");
    ASSERT_TRUE(writeGlb(*folded, path.string()).ok());
    Result<TreeModel> back = importGltf(path.string());
    ASSERT_TRUE(back.ok()) << back.error().message();
    ASSERT_EQ(back->leaves.size(), folded->leaves.size());
    for (const Leaf& leaf : back->leaves)
        EXPECT_EQ(leaf.vertexCount, 6u);
    for (float bad : {-1.0f, 81.0f, std::numeric_limits<float>::quiet_NaN()})
    {
        GeneratorOptions options;
        options.leafFold = bad;
        Result<TreeModel> model = generateTree(options);
        ASSERT_FALSE(model.ok()) << bad;
        EXPECT_EQ(model.error().element, "option --leaf-fold");
    }
}

// "broadleaf" is another name for the oak preset; unknown names are refused.
TEST(TreeGenerator, parsesPresetNames)
{
    TreePreset preset = TreePreset::Shrub;
    EXPECT_TRUE(parsePreset("broadleaf", preset));
    EXPECT_EQ(preset, TreePreset::Oak);
    for (TreePreset p : kPresets)
    {
        EXPECT_TRUE(parsePreset(presetName(p), preset));
        EXPECT_EQ(preset, p);
    }
    EXPECT_FALSE(parsePreset("palm", preset));
}

// Every preset must produce a model the rest of the pipeline accepts, with bark, a leaf
// material that alpha-tests, and the requested height at the top of its stems.
TEST(TreeGenerator, everyPresetValidates)
{
    for (TreePreset p : kPresets)
    {
        SCOPED_TRACE(presetName(p));
        TreeModel model = generate(p, 5, 800);
        EXPECT_TRUE(model.validate().ok());
        EXPECT_GT(model.barkTriangleCount(), 100u);
        EXPECT_LT(model.barkTriangleCount(), 30000u);
        ASSERT_EQ(model.materials.size(), 2u);
        EXPECT_FALSE(model.materials[0].isLeaf);
        EXPECT_TRUE(model.materials[1].isLeaf);
        EXPECT_TRUE(model.materials[1].doubleSided);
        EXPECT_EQ(model.materials[1].alphaCutoff, 0.5f);
        EXPECT_NE(model.materials[1].backColour, glm::vec3(0.0f));
        float stemTop = 0.0f;
        for (const SkeletonNode& n : model.skeleton)
            stemTop = std::max(stemTop, n.position.y);
        EXPECT_NEAR(stemTop, presetDefaultHeight(p), 1e-3f * presetDefaultHeight(p));
    }
}

// Nothing of a tree goes into the ground, not even with the fewest (largest) leaves, whose
// hanging ones the generator lifts onto it.
TEST(TreeGenerator, standsOnTheGround)
{
    for (TreePreset p : kPresets)
        for (std::uint32_t seed : {1u, 2u, 3u})
        {
            TreeModel model = generate(p, seed, 100, 16);
            EXPECT_GE(model.boundsMin.y, -1e-4f) << presetName(p) << " seed " << seed;
        }
}

// --height scales the whole tree: the stems' top is exactly the request.
TEST(TreeGenerator, heightOptionSetsStemTop)
{
    GeneratorOptions options;
    options.preset = TreePreset::Shrub;
    options.leafCount = 300;
    options.textureSize = 16;
    options.height = 4.0f;
    Result<TreeModel> model = generateTree(options);
    ASSERT_TRUE(model.ok());
    float stemTop = 0.0f;
    for (const SkeletonNode& n : model->skeleton)
        stemTop = std::max(stemTop, n.position.y);
    EXPECT_NEAR(stemTop, 4.0f, 1e-3f);
}

// Each leaf is one quad of positive area whose UVs span the whole texture, and every leaf
// vertex is inside the model bounds (which updateBounds computed from them).
TEST(TreeGenerator, leavesArePositiveQuadsInsideBounds)
{
    TreeModel model = generate(TreePreset::Shrub, 11, 1000);
    for (std::size_t i = 0; i < model.leaves.size(); ++i)
    {
        const Leaf& leaf = model.leaves[i];
        ASSERT_EQ(leaf.vertexCount, 4u);
        ASSERT_EQ(leaf.indexCount, 6u);
        EXPECT_GT(leaf.area, 0.0f) << "leaf " << i;
        EXPECT_EQ(leaf.uvMin, glm::vec2(0.0f));
        EXPECT_EQ(leaf.uvMax, glm::vec2(1.0f));
        EXPECT_NEAR(glm::length(leaf.normal), 1.0f, 1e-4f);
        for (std::uint32_t v = leaf.firstVertex; v < leaf.firstVertex + leaf.vertexCount; ++v)
        {
            const glm::vec3& p = model.leafVertices[v].position;
            EXPECT_TRUE(glm::all(glm::greaterThanEqual(p, model.boundsMin)) &&
                        glm::all(glm::lessThanEqual(p, model.boundsMax)));
        }
    }
}

// The leaf normal (from the triangles' winding) must agree with the vertex normals, or
// two-sided lighting would light the wrong side.
TEST(TreeGenerator, leafWindingMatchesVertexNormals)
{
    TreeModel model = generate(TreePreset::Birch, 4, 300);
    for (const Leaf& leaf : model.leaves)
        EXPECT_GT(glm::dot(leaf.normal, model.leafVertices[leaf.firstVertex].normal), 0.99f);
}

// Parents before children is what TreeModel::validate and the importer rely on; also the
// roots must be the trunks (one for oak, several for the shrub).
TEST(TreeGenerator, skeletonParentsPrecedeChildren)
{
    for (TreePreset p : {TreePreset::Oak, TreePreset::Shrub})
    {
        TreeModel model = generate(p, 9, 200);
        ASSERT_FALSE(model.skeleton.empty());
        int roots = 0;
        for (std::size_t i = 0; i < model.skeleton.size(); ++i)
        {
            EXPECT_LT(model.skeleton[i].parent, std::int32_t(i));
            EXPECT_GE(model.skeleton[i].radius, 0.0f);
            roots += model.skeleton[i].parent < 0 ? 1 : 0;
        }
        EXPECT_EQ(roots, p == TreePreset::Oak ? 1 : 9);
    }
}

// A leaf texture is a silhouette: some texels must be fully transparent (outside), some
// fully opaque (inside), and the transparent ones carry leaf colour (bleeding), not black.
TEST(LeafTexture, hasTransparentAndOpaqueTexelsWithBledColour)
{
    for (TreePreset p : kPresets)
    {
        SCOPED_TRACE(presetName(p));
        TextureImage image = drawLeafTexture(p, 64);
        ASSERT_EQ(image.rgba.size(), 64u * 64u * 4u);
        int transparent = 0, opaque = 0, darkTransparent = 0;
        for (std::size_t i = 0; i < image.rgba.size(); i += 4)
        {
            transparent += image.rgba[i + 3] == 0;
            opaque += image.rgba[i + 3] == 255;
            darkTransparent += image.rgba[i + 3] == 0 && image.rgba[i + 1] < 10;
        }
        EXPECT_GT(transparent, 64 * 64 / 10);
        EXPECT_GT(opaque, 64 * 64 / 20);
        EXPECT_EQ(darkTransparent, 0);
    }
}

// Bark is opaque and tiles: wrapping noise makes the first and last columns neighbours,
// so they differ little compared with the colour range.
TEST(LeafTexture, barkIsOpaqueAndTiles)
{
    TextureImage bark = drawBarkTexture(TreePreset::Conifer, 64, 64);
    double edgeDiff = 0.0;
    for (int y = 0; y < 64; ++y)
    {
        const std::size_t first = std::size_t(y) * 64 * 4, last = first + 63 * 4;
        edgeDiff += std::abs(int(bark.rgba[first + 1]) - int(bark.rgba[last + 1]));
        EXPECT_EQ(bark.rgba[first + 3], 255);
    }
    EXPECT_LT(edgeDiff / 64.0, 30.0);
}

// A .glb starts with the 12-byte header "glTF", version 2, total length.
TEST(GltfExporter, writesGlbWithMagic)
{
    TreeModel model = generate(TreePreset::Oak, 1, 100, 16);
    const std::filesystem::path path = testOut("generator-oak.glb");
    std::filesystem::remove(path);
    ASSERT_TRUE(writeGlb(model, path.string()).ok());
    std::ifstream in(path, std::ios::binary);
    char header[12] = {};
    in.read(header, 12);
    EXPECT_EQ(std::string(header, 4), "glTF");
    std::uint32_t version = 0, length = 0;
    std::memcpy(&version, header + 4, 4);
    std::memcpy(&length, header + 8, 4);
    EXPECT_EQ(version, 2u);
    EXPECT_EQ(length, std::filesystem::file_size(path));
}

// The same model gives the same bytes (PNG encoding included): packages built from a
// generated tree stay reproducible.
TEST(GltfExporter, encodingIsDeterministic)
{
    TreeModel model = generate(TreePreset::Conifer, 1, 100, 16);
    Result<std::vector<std::uint8_t>> a = encodeGlb(model), b = encodeGlb(model);
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_EQ(*a, *b);
}

// The file goes through a temp file + rename: when the directory doesn't exist the call
// fails and leaves nothing behind.
TEST(GltfExporter, failsWithoutWritingIntoMissingDirectory)
{
    TreeModel model = generate(TreePreset::Shrub, 1, 100, 16);
    const std::filesystem::path path = testOut("no-such-dir") / "tree.glb";
    std::filesystem::remove_all(path.parent_path());
    Result<void> written = writeGlb(model, path.string());
    EXPECT_FALSE(written.ok());
    EXPECT_FALSE(std::filesystem::exists(path));
}

// An invalid model (an index past the vertices) is refused before anything is written,
// and an existing file at the target stays as it was.
TEST(GltfExporter, refusesInvalidModelAndKeepsExistingFile)
{
    TreeModel model = generate(TreePreset::Shrub, 1, 100, 16);
    model.barkIndices[0] = std::uint32_t(model.barkVertices.size());
    const std::filesystem::path path = testOut("generator-keep.glb");
    {
        std::ofstream out(path, std::ios::binary);
        out << "old";
    }
    Result<void> written = writeGlb(model, path.string());
    ASSERT_FALSE(written.ok());
    EXPECT_EQ(written.error().file, path.string());
    EXPECT_EQ(std::filesystem::file_size(path), 3u);
}

// Over 65534 leaf vertices the leaf indices need 32 bits; the bytes must still form a
// complete file (length field = size) and hold both meshes' names.
TEST(GltfExporter, writesLargeLeafMeshWith32BitIndices)
{
    TreeModel model = generate(TreePreset::Conifer, 1, 20000, 16);
    ASSERT_GT(model.leafVertices.size(), 65535u);
    Result<std::vector<std::uint8_t>> bytes = encodeGlb(model);
    ASSERT_TRUE(bytes.ok());
    std::uint32_t length = 0, jsonLength = 0;
    std::memcpy(&length, bytes->data() + 8, 4);
    std::memcpy(&jsonLength, bytes->data() + 12, 4);
    EXPECT_EQ(length, bytes->size());
    const std::string json(reinterpret_cast<const char*>(bytes->data()) + 20, jsonLength);
    EXPECT_NE(json.find("\"Leaves\""), std::string::npos);
    EXPECT_NE(json.find("\"Bark\""), std::string::npos);
    EXPECT_NE(json.find("\"componentType\":5125"), std::string::npos); // UNSIGNED_INT
    EXPECT_NE(json.find("\"componentType\":5123"), std::string::npos); // UNSIGNED_SHORT (bark)
    EXPECT_NE(json.find("treelodSkeleton"), std::string::npos);
    EXPECT_NE(json.find("treelodBackColour"), std::string::npos);
    EXPECT_NE(json.find("\"MASK\""), std::string::npos);
}

// Round trip through the importer: what the exporter writes (geometry, skeleton extras,
// back colour extras, PNG textures) is what the importer reads. Positions, UVs, the
// skeleton and texels are stored exactly; normals may be renormalised (float rounding).
TEST(GltfExporter, roundTripsThroughImporter)
{
    TreeModel model = generate(TreePreset::Birch, 2, 400, 32);
    const std::filesystem::path path = testOut("generator-roundtrip.glb");
    ASSERT_TRUE(writeGlb(model, path.string()).ok());
    Result<TreeModel> back = importGltf(path.string());
    ASSERT_TRUE(back.ok()) << back.error().message();
    ASSERT_EQ(back->leaves.size(), model.leaves.size());
    ASSERT_EQ(back->leafVertices.size(), model.leafVertices.size());
    EXPECT_EQ(back->barkTriangleCount(), model.barkTriangleCount());
    for (std::size_t i = 0; i < model.leafVertices.size(); ++i)
    {
        ASSERT_EQ(back->leafVertices[i].position, model.leafVertices[i].position) << "leaf vertex " << i;
        ASSERT_EQ(back->leafVertices[i].uv, model.leafVertices[i].uv) << "leaf vertex " << i;
        ASSERT_NEAR(glm::length(back->leafVertices[i].normal - model.leafVertices[i].normal), 0.0f, 1e-5f);
    }
    ASSERT_EQ(back->skeleton.size(), model.skeleton.size());
    for (std::size_t i = 0; i < model.skeleton.size(); ++i)
    {
        EXPECT_EQ(back->skeleton[i].position, model.skeleton[i].position);
        EXPECT_EQ(back->skeleton[i].radius, model.skeleton[i].radius);
        EXPECT_EQ(back->skeleton[i].parent, model.skeleton[i].parent);
    }
    std::size_t leafMaterial = back->materials.size();
    for (std::size_t m = 0; m < back->materials.size(); ++m)
        if (back->materials[m].isLeaf)
            leafMaterial = m;
    ASSERT_LT(leafMaterial, back->materials.size());
    EXPECT_EQ(back->materials[leafMaterial].backColour, model.materials[1].backColour);
    EXPECT_TRUE(back->materials[leafMaterial].doubleSided);
    ASSERT_GE(back->materials[leafMaterial].texture, 0);
    EXPECT_EQ(back->textures[std::size_t(back->materials[leafMaterial].texture)].rgba, model.textures[1].rgba);
}
