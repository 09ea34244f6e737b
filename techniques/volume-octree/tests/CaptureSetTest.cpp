// CaptureSet: the camera model against the reference renderer, validation, the cameras.json folder
// (read errors, whole-or-nothing writes) and synthesis from a generated oak.
#include "TreeLod/CaptureSet.h"
#include "TreeLod/ReferenceRenderer.h"

#include "TestOutput.h"
#include "TestTrees.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>

using namespace TreeLod;

namespace
{
    namespace fs = std::filesystem;
    using Json = nlohmann::json;

    constexpr double NaN = std::numeric_limits<double>::quiet_NaN();

    CameraSpec specAt(const glm::vec3& position, const glm::vec3& target = glm::vec3(0.0f), float fov = 40.0f)
    {
        CameraSpec spec;
        spec.position = position;
        spec.target = target;
        spec.fovYDegrees = fov;
        spec.nearClip = 0.1f;
        spec.farClip = 100.0f;
        return spec;
    }

    /// Colours on the 8-bit grid, alpha a ramp: they survive a PNG unchanged.
    Image pattern(int width, int height, int seed)
    {
        Image image(width, height);
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x)
                image.at(x, y) = glm::vec4(float((x * 7 + seed) % 256), float((y * 5 + seed) % 256),
                                           float((x + y + seed) % 256), float((x * 3 + y) % 256)) / 255.0f;
        return image;
    }

    /// Two 32 x 32 cameras looking at the box [-1, 1]^3 from 5 m: cam00 from +z, cam01 from +x.
    CaptureSet tinySet()
    {
        CaptureSet set;
        set.volumeMin = glm::dvec3(-1.0);
        set.volumeMax = glm::dvec3(1.0);
        set.cameras.push_back(captureCameraFromSpec(specAt({0.0f, 0.0f, 5.0f}), 32, 32, "cam00"));
        set.cameras.push_back(captureCameraFromSpec(specAt({5.0f, 1.0f, 0.0f}), 32, 32, "cam01"));
        set.images.push_back(pattern(32, 32, 1));
        set.images.push_back(pattern(32, 32, 2));
        return set;
    }

    template <typename T>
    void expectError(const Result<T>& r, const std::string& file, const std::string& element, const std::string& reason)
    {
        ASSERT_FALSE(r.ok());
        EXPECT_EQ(r.error().file, file) << r.error().message();
        EXPECT_NE(r.error().element.find(element), std::string::npos) << r.error().message();
        EXPECT_NE(r.error().reason.find(reason), std::string::npos) << r.error().message();
    }

    std::string jsonPath(const std::string& dir) { return (fs::path(dir) / CAPTURE_SET_FILE).string(); }

    Json loadJson(const std::string& dir)
    {
        std::ifstream in(jsonPath(dir));
        return Json::parse(in);
    }

    void saveText(const std::string& path, const std::string& text)
    {
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        out << text;
    }

    void saveJson(const std::string& dir, const Json& j) { saveText(jsonPath(dir), j.dump(2)); }

    /// The set in `dir` read back after `edit` changed its cameras.json (a copy of `good`).
    Result<CaptureSet> readEdited(const std::string& dir, const Json& good, const std::function<void(Json&)>& edit)
    {
        Json j = good;
        edit(j);
        saveJson(dir, j);
        return readCaptureSet(dir);
    }

    /// A fresh folder holding tinySet().
    std::string writtenTinySet(const std::string& name)
    {
        const std::string dir = test::freshTestDir("capture", name) + "/set";
        Result<void> r = writeCaptureSet(tinySet(), dir);
        EXPECT_TRUE(r.ok()) << r.error().message();
        return dir;
    }

    /// Names in `dir` that look like a temporary file or folder.
    std::vector<std::string> temporaries(const std::string& dir)
    {
        std::vector<std::string> out;
        for (const fs::directory_entry& e : fs::recursive_directory_iterator(dir))
            if (e.path().filename().string().find(".tmp") != std::string::npos)
                out.push_back(e.path().string());
        return out;
    }

    /// One untextured leaf quad: corners centre -+u -+v.
    TreeModel quadModel(const glm::vec3& centre, const glm::vec3& u, const glm::vec3& v)
    {
        TreeModel m;
        m.materials.push_back(test::leafMaterial("leaf"));
        test::addQuadLeaf(m, centre, u, v, glm::normalize(glm::cross(u, v)));
        m.updateBounds();
        return m;
    }

    double degrees(double radians) { return radians * 180.0 / 3.14159265358979323846; }
}

// ---- camera model ----------------------------------------------------------------------------

TEST(CaptureSet, cameraPositionForwardProjectAndRays)
{
    const CameraSpec spec = specAt({1.0f, 2.0f, 6.0f}, {0.5f, 1.0f, 0.0f}, 30.0f);
    const CaptureCamera camera = captureCameraFromSpec(spec, 64, 48, "cam");
    EXPECT_EQ(camera.image, "cam.png");
    EXPECT_NEAR(camera.fx, 48.0 / (2.0 * std::tan(15.0 * 3.14159265358979323846 / 180.0)), 1e-9);
    EXPECT_EQ(camera.fx, camera.fy);
    EXPECT_EQ(camera.cx, 32.0);
    EXPECT_EQ(camera.cy, 24.0);

    const glm::dvec3 position(spec.position), target(spec.target);
    EXPECT_NEAR(glm::length(camera.position() - position), 0.0, 1e-9);
    EXPECT_NEAR(glm::length(camera.forward() - glm::normalize(target - position)), 0.0, 1e-9);

    glm::dvec2 pixel;
    double depth = 0.0;
    ASSERT_TRUE(camera.project(target, pixel, depth));
    EXPECT_NEAR(pixel.x, 32.0, 1e-9);
    EXPECT_NEAR(pixel.y, 24.0, 1e-9);
    EXPECT_NEAR(depth, glm::length(target - position), 1e-9);
    // Up in the world is up in the image (v decreases), right is right.
    ASSERT_TRUE(camera.project(target + glm::dvec3(0.0, 0.1, 0.0), pixel, depth));
    EXPECT_LT(pixel.y, 24.0);
    // Behind the camera, and at its centre: not projected.
    EXPECT_FALSE(camera.project(position - camera.forward(), pixel, depth));
    EXPECT_LT(depth, 0.0);
    EXPECT_FALSE(camera.project(position, pixel, depth));

    // rayDirection inverts project.
    std::mt19937 random(7);
    std::uniform_real_distribution<double> coordinate(-3.0, 3.0);
    for (int i = 0; i < 50; ++i)
    {
        const glm::dvec3 p(coordinate(random), coordinate(random), coordinate(random));
        if (!camera.project(p, pixel, depth))
            continue;
        EXPECT_NEAR(glm::length(camera.rayDirection(pixel) - glm::normalize(p - position)), 0.0, 1e-9);
        EXPECT_NEAR(glm::dot(p - position, camera.forward()), depth, 1e-9);
    }
    EXPECT_NEAR(glm::length(camera.rayDirection({32.0, 24.0}) - camera.forward()), 0.0, 1e-12);

    CameraSpec ortho = spec;
    ortho.orthographic = true;
    EXPECT_THROW(captureCameraFromSpec(ortho, 64, 48, "o"), std::invalid_argument);
}

TEST(CaptureSet, projectMatchesTheSpecMatrices)
{
    // The renderer's pixel of a point: NDC from projection * view, x right, y up, rows top down.
    std::mt19937 random(3);
    std::uniform_real_distribution<float> coordinate(-4.0f, 4.0f), fov(20.0f, 70.0f);
    for (int trial = 0; trial < 20; ++trial)
    {
        const int width = 16 + 8 * (trial % 5), height = 16 + 4 * (trial % 7);
        CameraSpec spec = specAt({coordinate(random), coordinate(random), 10.0f + coordinate(random)},
                                 {coordinate(random) * 0.2f, coordinate(random) * 0.2f, 0.0f}, fov(random));
        const CaptureCamera camera = captureCameraFromSpec(spec, width, height, "c");
        const glm::dmat4 exact = glm::perspective(glm::radians(double(spec.fovYDegrees)), double(width) / height,
                                                  double(spec.nearClip), double(spec.farClip)) *
                                 glm::lookAt(glm::dvec3(spec.position), glm::dvec3(spec.target), glm::dvec3(spec.up));
        const glm::dmat4 single(spec.projectionMatrix(float(width) / float(height)) * spec.viewMatrix());
        for (int i = 0; i < 20; ++i)
        {
            const glm::dvec3 p(coordinate(random), coordinate(random), coordinate(random));
            glm::dvec2 pixel;
            double depth = 0.0;
            ASSERT_TRUE(camera.project(p, pixel, depth));
            for (const glm::dmat4* m : {&exact, &single})
            {
                const glm::dvec4 clip = *m * glm::dvec4(p, 1.0);
                const glm::dvec2 expected((clip.x / clip.w + 1.0) * 0.5 * width,
                                          (1.0 - clip.y / clip.w) * 0.5 * height);
                const double tolerance = m == &exact ? 1e-6 : 1e-3;
                EXPECT_NEAR(pixel.x, expected.x, tolerance) << trial << " " << i;
                EXPECT_NEAR(pixel.y, expected.y, tolerance) << trial << " " << i;
                EXPECT_NEAR(depth, clip.w, m == &exact ? 1e-9 : 1e-4);
            }
        }
    }
}

TEST(CaptureSet, projectLinesUpWithTheReferenceRenderer)
{
    // Pixels whose centre projects well inside the leaf quad are covered, well outside are not.
    const glm::vec3 centre(0.1f, 0.2f, 0.0f), u(0.6f, 0.1f, 0.0f), v(-0.1f, 0.5f, 0.2f);
    const TreeModel model = quadModel(centre, u, v);
    const CameraSpec spec = specAt({0.3f, 0.5f, 3.0f}, {0.0f, 0.2f, 0.0f}, 35.0f);
    const int width = 48, height = 32;
    RenderOptions options;
    options.width = width;
    options.height = height;
    options.samplesPerPixel = 1;
    options.transparentBackground = true;
    const RenderImages images = ReferenceRenderer(model).render(spec, options);
    const CaptureCamera camera = captureCameraFromSpec(spec, width, height, "c");

    glm::dvec2 corners[4];
    const glm::vec3 world[4] = {centre - u - v, centre + u - v, centre + u + v, centre - u + v};
    for (int k = 0; k < 4; ++k)
    {
        double depth = 0.0;
        ASSERT_TRUE(camera.project(glm::dvec3(world[k]), corners[k], depth));
    }
    double area = 0.0;
    for (int k = 0; k < 4; ++k)
        area += corners[k].x * corners[(k + 1) % 4].y - corners[(k + 1) % 4].x * corners[k].y;
    int inside = 0, outside = 0;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
        {
            const glm::dvec2 p(x + 0.5, y + 0.5);
            double margin = INFINITY; // signed distance to the outline in pixels, > 0 inside
            for (int k = 0; k < 4; ++k)
            {
                const glm::dvec2 a = corners[k], edge = corners[(k + 1) % 4] - a;
                const double cross = edge.x * (p.y - a.y) - edge.y * (p.x - a.x);
                margin = std::min(margin, (area > 0.0 ? cross : -cross) / glm::length(edge));
            }
            const float alpha = images.alpha[std::size_t(y) * width + x];
            if (margin > 0.01)
            {
                ++inside;
                EXPECT_EQ(alpha, 1.0f) << x << ", " << y << " margin " << margin;
            }
            else if (margin < -0.01)
            {
                ++outside;
                EXPECT_EQ(alpha, 0.0f) << x << ", " << y << " margin " << margin;
            }
        }
    EXPECT_GT(inside, 50);
    EXPECT_GT(outside, 50);
}

// ---- validation --------------------------------------------------------------------------------

TEST(CaptureSet, validateAcceptsTheTinySetAndACameraInsideTheBox)
{
    CaptureSet set = tinySet();
    Result<void> r = set.validate("label");
    EXPECT_TRUE(r.ok()) << r.error().message();
    set.cameras[1] = captureCameraFromSpec(specAt({0.0f, 0.0f, 0.5f}, {0.0f, 0.0f, -1.0f}), 32, 32, "inside");
    r = set.validate("label");
    EXPECT_TRUE(r.ok()) << r.error().message();
}

TEST(CaptureSet, validateRefusesBadSets)
{
    const std::string label = "set.json";
    {
        CaptureSet set = tinySet();
        set.cameras.clear();
        set.images.clear();
        expectError(set.validate(label), label, "cameras", "no camera");
    }
    {
        CaptureSet set = tinySet();
        set.volumeMax.y = -1.0;
        expectError(set.validate(label), label, "volume", "min < max");
        set.volumeMax.y = NaN;
        expectError(set.validate(label), label, "volume", "finite");
    }
    {
        CaptureSet set = tinySet();
        set.images.pop_back();
        expectError(set.validate(label), label, "images", "1 images for 2 cameras");
    }
    {
        CaptureSet set = tinySet();
        set.cameras[1].name = "cam00";
        expectError(set.validate(label), label, "camera 'cam00'", "unique");
    }
    {
        CaptureSet set = tinySet();
        set.cameras[1].worldToCamera[3][1] = NaN;
        expectError(set.validate(label), label, "camera 'cam01'", "not finite");
    }
    {
        CaptureSet set = tinySet();
        set.cameras[1].worldToCamera[0] *= 2.0; // scale
        expectError(set.validate(label), label, "camera 'cam01'", "not rigid");
        set = tinySet();
        set.cameras[1].worldToCamera[1][3] = 0.5; // projective last row
        expectError(set.validate(label), label, "camera 'cam01'", "last row");
        set = tinySet();
        set.cameras[1].worldToCamera[0] *= -1.0; // mirror
        expectError(set.validate(label), label, "camera 'cam01'", "mirrors");
    }
    {
        CaptureSet set = tinySet();
        set.cameras[0].fy = 0.0;
        expectError(set.validate(label), label, "camera 'cam00'", "positive");
        set = tinySet();
        set.cameras[0].cx = NaN;
        expectError(set.validate(label), label, "camera 'cam00'", "cx, cy");
    }
    {
        CaptureSet set = tinySet();
        set.images[1] = Image();
        expectError(set.validate(label), label, "camera 'cam01'", "no image");
        set.images[1] = pattern(32, 16, 0);
        expectError(set.validate(label), label, "camera 'cam01'", "32x16");
        set.images[1] = pattern(32, 32, 0);
        set.images[1].at(3, 4).g = float(NaN);
        expectError(set.validate(label), label, "camera 'cam01'", "pixel (3, 4)");
    }
    {
        // Looking away: the whole box behind the camera.
        CaptureSet set = tinySet();
        set.cameras[0] = captureCameraFromSpec(specAt({0.0f, 0.0f, 5.0f}, {0.0f, 0.0f, 10.0f}), 32, 32, "cam00");
        expectError(set.validate(label), label, "camera 'cam00'", "behind the camera");
        // Looking sideways: corners in front, but far outside the image.
        set.cameras[0] = captureCameraFromSpec(specAt({0.0f, 0.0f, 5.0f}, {10.0f, 0.0f, 5.0f}), 32, 32, "cam00");
        expectError(set.validate(label), label, "camera 'cam00'", "outside the image");
        // The principal point moved far off: the box misses the image.
        set.cameras[0] = tinySet().cameras[0];
        set.cameras[0].cx = 500.0;
        expectError(set.validate(label), label, "camera 'cam00'", "outside the image");
    }
}

// ---- folder: writing ---------------------------------------------------------------------------

TEST(CaptureSet, writeThenReadKeepsCamerasAndImages)
{
    const CaptureSet set = tinySet();
    const std::string dir = writtenTinySet("roundtrip");
    Result<CaptureSet> read = readCaptureSet(dir);
    ASSERT_TRUE(read.ok()) << read.error().message();
    EXPECT_EQ(read->volumeMin, set.volumeMin);
    EXPECT_EQ(read->volumeMax, set.volumeMax);
    ASSERT_EQ(read->cameras.size(), 2u);
    for (std::size_t i = 0; i < 2; ++i)
    {
        const CaptureCamera &a = set.cameras[i], &b = read->cameras[i];
        EXPECT_EQ(a.name, b.name);
        EXPECT_EQ(a.image, b.image);
        EXPECT_EQ(a.width, b.width);
        EXPECT_EQ(a.height, b.height);
        EXPECT_EQ(a.fx, b.fx);
        EXPECT_EQ(a.fy, b.fy);
        EXPECT_EQ(a.cx, b.cx);
        EXPECT_EQ(a.cy, b.cy);
        EXPECT_EQ(a.worldToCamera, b.worldToCamera); // JSON keeps doubles exactly
        float worst = 0.0f; // on the 8-bit grid: the same up to rounding
        for (std::size_t p = 0; p < set.images[i].pixels.size(); ++p)
            for (int k = 0; k < 4; ++k)
                worst = std::max(worst, std::abs(set.images[i].pixels[p][k] - read->images[i].pixels[p][k]));
        EXPECT_LE(worst, 1e-6f);
    }
    const Json j = loadJson(dir);
    EXPECT_EQ(j["format"], "treelod-capture");
    EXPECT_EQ(j["version"], CAPTURE_SET_FORMAT_VERSION);
    // Row-major: the translation is the last column.
    EXPECT_EQ(j["cameras"][0]["worldToCamera"][11].get<double>(), set.cameras[0].worldToCamera[3][2]);
    EXPECT_TRUE(temporaries(fs::path(dir).parent_path().string()).empty());
}

TEST(CaptureSet, writeNeverOverwritesAndLeavesNoTemporaries)
{
    const std::string root = test::freshTestDir("capture", "whole-or-nothing");

    // An existing cameras.json is refused and kept byte for byte.
    const std::string dir = root + "/set";
    ASSERT_TRUE(writeCaptureSet(tinySet(), dir).ok());
    std::ifstream before(jsonPath(dir));
    const std::string original((std::istreambuf_iterator<char>(before)), std::istreambuf_iterator<char>());
    CaptureSet other = tinySet();
    other.volumeMax = glm::dvec3(2.0);
    expectError(writeCaptureSet(other, dir), dir + "/cameras.json", "", "already exists");
    std::ifstream after(jsonPath(dir));
    EXPECT_EQ(std::string((std::istreambuf_iterator<char>(after)), std::istreambuf_iterator<char>()), original);

    // An image of that name in the folder is refused too.
    const std::string withImage = root + "/with-image";
    fs::create_directories(withImage);
    saveText(withImage + "/cam01.png", "mine");
    expectError(writeCaptureSet(tinySet(), withImage), withImage + "/cam01.png", "camera 'cam01'", "already exists");
    EXPECT_FALSE(fs::exists(jsonPath(withImage)));
    EXPECT_FALSE(fs::exists(withImage + "/cam00.png"));

    // An existing empty folder, a folder with other files, a missing nested one: all written.
    fs::create_directories(root + "/empty");
    fs::create_directories(root + "/others");
    saveText(root + "/others/notes.txt", "keep me");
    for (const std::string& target : {root + "/empty", root + "/others/", root + "/a/b/c"})
    {
        Result<void> r = writeCaptureSet(tinySet(), target);
        ASSERT_TRUE(r.ok()) << r.error().message();
        Result<CaptureSet> read = readCaptureSet(target);
        EXPECT_TRUE(read.ok()) << read.error().message();
    }
    EXPECT_TRUE(fs::exists(root + "/others/notes.txt"));

    // A failure after some images are written (a name the file system refuses) leaves nothing.
    CaptureSet tooLong = tinySet();
    tooLong.cameras[1].image = std::string(300, 'x') + ".png";
    const std::string failed = root + "/failed";
    Result<void> r = writeCaptureSet(tooLong, failed);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().element, "camera 'cam01'") << r.error().message();
    EXPECT_FALSE(fs::exists(failed));

    // An invalid set or image name is refused before anything is written.
    CaptureSet invalid = tinySet();
    invalid.cameras[0].worldToCamera[2][2] = NaN;
    expectError(writeCaptureSet(invalid, failed), failed + "/cameras.json", "camera 'cam00'", "not finite");
    CaptureSet badName = tinySet();
    badName.cameras[0].image = "../cam00.png";
    expectError(writeCaptureSet(badName, failed), failed + "/cameras.json", "camera 'cam00'", ".png");
    badName.cameras[0].image = "cam01.png";
    expectError(writeCaptureSet(badName, failed), failed + "/cameras.json", "camera 'cam01'", "also cameras[0]");
    EXPECT_FALSE(fs::exists(failed));

    EXPECT_TRUE(temporaries(root).empty()) << temporaries(root).front();
}

// ---- folder: reading errors --------------------------------------------------------------------

TEST(CaptureSet, readNamesMissingAndMismatchedImages)
{
    const std::string dir = writtenTinySet("read-images");
    fs::rename(dir + "/cam01.png", dir + "/moved.png");
    expectError(readCaptureSet(dir), dir + "/cam01.png", "camera 'cam01'", "does not exist");

    ASSERT_TRUE(writePng(dir + "/cam01.png", pattern(16, 32, 0)).ok());
    expectError(readCaptureSet(dir), dir + "/cam01.png", "camera 'cam01'", "16x32 pixels, but cameras.json says 32x32");

    saveText(dir + "/cam01.png", "not a png");
    expectError(readCaptureSet(dir), dir + "/cam01.png", "camera 'cam01'", "not an image");

    const std::string missing = test::freshTestDir("capture", "read-missing");
    expectError(readCaptureSet(missing + "/nothing"), missing + "/nothing", "", "folder does not exist");
    expectError(readCaptureSet(missing), missing + "/cameras.json", "", "does not exist");
}

TEST(CaptureSet, readNamesBadCameras)
{
    const std::string dir = writtenTinySet("read-cameras");
    const std::string file = jsonPath(dir);
    const Json good = loadJson(dir);
    auto readWith = [&](const std::function<void(Json&)>& edit) { return readEdited(dir, good, edit); };
    ASSERT_TRUE(readWith([](Json&) {}).ok());

    // NaN and infinity become null in JSON.
    expectError(readWith([](Json& j) { j["cameras"][1]["worldToCamera"][5] = nullptr; }), file,
                "cameras[1].worldToCamera[5]", "not null");
    expectError(readWith([](Json& j) { j["cameras"][0]["worldToCamera"][0] = 2.0; }), file, "camera 'cam00'",
                "not rigid");
    expectError(readWith([](Json& j) { j["cameras"][0]["worldToCamera"][12] = 0.5; }), file, "camera 'cam00'",
                "last row");
    // Turned half round its own y axis: looking away from the volume.
    expectError(readWith([](Json& j) {
                    for (int i : {0, 1, 2, 3, 8, 9, 10, 11})
                        j["cameras"][0]["worldToCamera"][i] = -j["cameras"][0]["worldToCamera"][i].get<double>();
                }),
                file, "camera 'cam00'", "sees nothing");
    expectError(readWith([](Json& j) { j["cameras"][1]["name"] = "cam00"; }), file, "camera 'cam00'", "unique");
    expectError(readWith([](Json& j) { j["cameras"][1]["fx"] = -3.0; }), file, "camera 'cam01'", "positive");
    expectError(readWith([](Json& j) { j["volume"]["min"][2] = 5.0; }), file, "volume", "min < max");
    expectError(readWith([](Json& j) { j["cameras"] = Json::array(); }), file, "cameras", "no camera");
}

TEST(CaptureSet, readNamesBadJson)
{
    const std::string dir = writtenTinySet("read-json");
    const std::string file = jsonPath(dir);
    const Json good = loadJson(dir);
    auto readWith = [&](const std::function<void(Json&)>& edit) { return readEdited(dir, good, edit); };

    expectError(readWith([](Json& j) { j["format"] = "treelod-package"; }), file, "format",
                "not a TreeLod capture set");
    expectError(readWith([](Json& j) { j.erase("format"); }), file, "format", "missing");
    expectError(readWith([](Json& j) { j["version"] = 2; }), file, "version", "version 2 is not supported");
    expectError(readWith([](Json& j) { j["version"] = "1"; }), file, "version", "whole number, not string");
    expectError(readWith([](Json& j) { j.erase("volume"); }), file, "volume", "missing");
    expectError(readWith([](Json& j) { j["volume"].erase("max"); }), file, "volume.max", "missing");
    expectError(readWith([](Json& j) { j["volume"]["min"] = {0, 0}; }), file, "volume.min", "array of 3 numbers");
    expectError(readWith([](Json& j) { j.erase("cameras"); }), file, "cameras", "missing");
    expectError(readWith([](Json& j) { j["cameras"][1].erase("fx"); }), file, "cameras[1].fx", "missing");
    expectError(readWith([](Json& j) { j["cameras"][1]["fx"] = "300"; }), file, "cameras[1].fx",
                "must be a number, not string");
    expectError(readWith([](Json& j) { j["cameras"][0]["width"] = 32.5; }), file, "cameras[0].width", "whole number");
    expectError(readWith([](Json& j) { j["cameras"][0]["height"] = 0; }), file, "cameras[0].height", "whole number");
    expectError(readWith([](Json& j) { j["cameras"][0]["worldToCamera"].erase(15); }), file,
                "cameras[0].worldToCamera", "16 numbers");
    expectError(readWith([](Json& j) { j["cameras"][0]["image"] = "../cam00.png"; }), file, "cameras[0].image",
                "not the name of a file in the folder");
    expectError(readWith([](Json& j) { j["cameras"][0]["name"] = ""; }), file, "cameras[0].name", "empty");
    expectError(readWith([](Json& j) { j["cameras"][0] = 3; }), file, "cameras[0]", "must be an object");

    // Syntax: a missing comma on line 2, a truncated file, a number beyond a double.
    saveText(file, "{\"format\": \"treelod-capture\"\n \"version\": 1}");
    expectError(readCaptureSet(dir), file, "line 2, column 10", "not valid JSON");
    const std::string text = good.dump(2);
    saveText(file, text.substr(0, text.size() / 2));
    expectError(readCaptureSet(dir), file, "line ", "not valid JSON");
    saveText(file, "{\"format\": \"treelod-capture\", \"version\": 1e999}");
    expectError(readCaptureSet(dir), file, "", "not valid JSON");
}

// ---- synthesis ---------------------------------------------------------------------------------

TEST(CaptureSet, synthesiseWriteReadRoundTrip)
{
    const TreeModel& oak = test::generatedOak(256);
    CaptureSynthesisOptions options;
    options.cameraCount = 4;
    options.resolution = 32;
    options.samplesPerPixel = 1;
    std::vector<float> fractions;
    Result<CaptureSet> set = synthesiseCaptureSet(oak, options, "oak", [&](const std::string& step, float f) {
        EXPECT_EQ(step, "capture: views");
        fractions.push_back(f);
    });
    ASSERT_TRUE(set.ok()) << set.error().message();
    EXPECT_EQ(fractions.front(), 0.0f);
    EXPECT_EQ(fractions.back(), 1.0f);

    // The volume: the vertices' box grown by 2 % of its largest side.
    glm::dvec3 lo(INFINITY), hi(-INFINITY);
    for (const std::vector<Vertex>* vertices : {&oak.barkVertices, &oak.leafVertices})
        for (const Vertex& v : *vertices)
        {
            lo = glm::min(lo, glm::dvec3(v.position));
            hi = glm::max(hi, glm::dvec3(v.position));
        }
    const glm::dvec3 extent = hi - lo;
    const double grow = 0.02 * std::max({extent.x, extent.y, extent.z});
    EXPECT_NEAR(glm::length(set->volumeMin - (lo - grow)), 0.0, 1e-9);
    EXPECT_NEAR(glm::length(set->volumeMax - (hi + grow)), 0.0, 1e-9);

    // n = 4: two at 10 degrees (azimuth 0 = +z, 180), one at 40 degrees (azimuth 180), one at 75.
    const glm::dvec3 centre = 0.5 * (set->volumeMin + set->volumeMax);
    const double radius = 0.5 * glm::length(set->volumeMax - set->volumeMin);
    const double azimuths[4] = {0.0, 180.0, 180.0, 0.0}, elevations[4] = {10.0, 10.0, 40.0, 75.0};
    ASSERT_EQ(set->cameras.size(), 4u);
    ASSERT_EQ(set->images.size(), 4u);
    for (std::size_t i = 0; i < 4; ++i)
    {
        const CaptureCamera& c = set->cameras[i];
        EXPECT_EQ(c.name, "cam0" + std::to_string(i));
        EXPECT_EQ(c.image, c.name + ".png");
        EXPECT_EQ(c.width, 32);
        const glm::dvec3 offset = c.position() - centre;
        EXPECT_NEAR(glm::length(offset), 3.0 * radius, 1e-5 * radius) << i;
        EXPECT_NEAR(degrees(std::asin(offset.y / glm::length(offset))), elevations[i], 1e-4) << i;
        EXPECT_NEAR(std::fmod(degrees(std::atan2(offset.x, offset.z)) + 360.0, 360.0), azimuths[i], 1e-3) << i;
        EXPECT_NEAR(glm::length(c.forward() + glm::normalize(offset)), 0.0, 1e-6) << i;
        // The tree is in the middle of the picture, the corners are background.
        const Image& image = set->images[i];
        EXPECT_GT(image.at(16, 16).a + image.at(15, 15).a + image.at(16, 20).a, 0.0f) << i;
        EXPECT_EQ(image.at(0, 0).a, 0.0f) << i;
    }

    const std::string dir = test::freshTestDir("capture", "synthesised") + "/oak";
    Result<void> written = writeCaptureSet(set.value(), dir);
    ASSERT_TRUE(written.ok()) << written.error().message();
    Result<CaptureSet> read = readCaptureSet(dir);
    ASSERT_TRUE(read.ok()) << read.error().message();
    EXPECT_EQ(read->volumeMin, set->volumeMin);
    EXPECT_EQ(read->volumeMax, set->volumeMax);
    for (std::size_t i = 0; i < 4; ++i)
    {
        const CaptureCamera &a = set->cameras[i], &b = read->cameras[i];
        EXPECT_EQ(a.name, b.name);
        EXPECT_EQ(a.fx, b.fx);
        EXPECT_EQ(a.cy, b.cy);
        EXPECT_EQ(a.worldToCamera, b.worldToCamera);
        float worst = 0.0f;
        for (std::size_t p = 0; p < a.width * std::size_t(a.height); ++p)
            for (int k = 0; k < 4; ++k)
                worst = std::max(worst, std::abs(set->images[i].pixels[p][k] - read->images[i].pixels[p][k]));
        EXPECT_LE(worst, 1.0f / 255.0f + 1e-6f) << i; // 8-bit PNG
    }
}

TEST(CaptureSet, synthesisePlacesCamerasOnRings)
{
    const TreeModel model = quadModel({0.0f, 1.0f, 0.0f}, {0.5f, 0.0f, 0.0f}, {0.0f, 0.5f, 0.0f});
    CaptureSynthesisOptions options;
    options.resolution = 16;
    options.samplesPerPixel = 1;
    options.distanceInRadii = 2.0f;
    const auto placements = [&](int n) {
        options.cameraCount = n;
        Result<CaptureSet> set = synthesiseCaptureSet(model, options, "quad");
        EXPECT_TRUE(set.ok()) << set.error().message();
        std::vector<glm::dvec2> out; // (azimuth, elevation)
        if (!set)
            return out;
        const glm::dvec3 centre = 0.5 * (set->volumeMin + set->volumeMax);
        const double radius = 0.5 * glm::length(set->volumeMax - set->volumeMin);
        for (const CaptureCamera& c : set->cameras)
        {
            const glm::dvec3 d = c.position() - centre;
            EXPECT_NEAR(glm::length(d), 2.0 * radius, 1e-5 * radius);
            out.push_back({std::fmod(degrees(std::atan2(d.x, d.z)) + 360.0, 360.0),
                           degrees(std::asin(d.y / glm::length(d)))});
        }
        return out;
    };
    // A flat model (extent 0 along z) still has a volume.
    std::vector<glm::dvec2> one = placements(1);
    ASSERT_EQ(one.size(), 1u);
    EXPECT_NEAR(one[0].x, 0.0, 1e-3);
    EXPECT_NEAR(one[0].y, 10.0, 1e-4);

    const std::vector<glm::dvec2> seven = placements(7);
    const glm::dvec2 expected[7] = {{0, 10}, {90, 10}, {180, 10}, {270, 10}, {90, 40}, {270, 40}, {0, 75}};
    ASSERT_EQ(seven.size(), 7u);
    for (int i = 0; i < 7; ++i)
    {
        EXPECT_NEAR(std::fmod(seven[i].x + 0.5, 360.0) - 0.5, expected[i].x, 1e-3) << i;
        EXPECT_NEAR(seven[i].y, expected[i].y, 1e-4) << i;
    }
}

TEST(CaptureSet, synthesiseRefusesBadOptionsAndEmptyModels)
{
    const TreeModel model = quadModel({0.0f, 1.0f, 0.0f}, {0.5f, 0.0f, 0.0f}, {0.0f, 0.5f, 0.0f});
    const auto withOptions = [&](const std::function<void(CaptureSynthesisOptions&)>& edit) {
        CaptureSynthesisOptions options;
        options.resolution = 16;
        options.samplesPerPixel = 1;
        edit(options);
        return synthesiseCaptureSet(model, options, "tree.glb");
    };
    expectError(withOptions([](CaptureSynthesisOptions& o) { o.cameraCount = 0; }), "tree.glb", "cameraCount",
                "[1, 256]");
    expectError(withOptions([](CaptureSynthesisOptions& o) { o.cameraCount = 257; }), "tree.glb", "cameraCount",
                "[1, 256]");
    expectError(withOptions([](CaptureSynthesisOptions& o) { o.resolution = 8; }), "tree.glb", "resolution",
                "[16, 4096]");
    expectError(withOptions([](CaptureSynthesisOptions& o) { o.samplesPerPixel = 3; }), "tree.glb", "samplesPerPixel",
                "square");
    expectError(withOptions([](CaptureSynthesisOptions& o) { o.fovYDegrees = 180.0f; }), "tree.glb", "fovYDegrees",
                "(0, 180)");
    expectError(withOptions([](CaptureSynthesisOptions& o) { o.distanceInRadii = 0.0f; }), "tree.glb",
                "distanceInRadii", "positive");
    expectError(synthesiseCaptureSet(TreeModel(), CaptureSynthesisOptions(), "empty.glb"), "empty.glb", "model",
                "no extent");
}
