// Shared fixture of the Ogre tests: one headless Root per test binary (Ogre allows one
// Root per process), with Plugin_TreeLod loaded from its .so like an application would.
#pragma once

#include "TreeLod/Image.h"
#include "TreeLod/ImageMetrics.h"
#include "TreeLod/OffscreenRenderer.h"
#include "TreeLod/RgbaImageConversion.h"
#include "TreeLod/TechniqueRegistry.h"
#include "TreeLod/TreeViews.h"

#include <OgreMovableObject.h>
#include <OgreSceneManager.h>
#include <OgreSceneQuery.h>

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

namespace TreeLod
{
    /// The Ogre test binaries' environment (OgreTestMain.cpp registers it): the headless
    /// renderer, created on first use, and the objects tests keep across tests (baked assets,
    /// placed objects). TearDown destroys the kept objects, newest first, and then the renderer,
    /// before main() returns: nothing Ogre owns is left to static destruction.
    class OgreEnvironment : public ::testing::Environment
    {
    public:
        static OffscreenRenderer& renderer()
        {
            State& s = state();
            if (!s.renderer)
            {
                OffscreenOptions options;
                options.pluginPath = TREELOD_PLUGIN_PATH;
                options.logFile = outDir() + "/" + logName();
                s.renderer = std::make_unique<OffscreenRenderer>(options);
            }
            return *s.renderer;
        }

        /// The object kept under `key`, made by `make` on first use (after the renderer, so
        /// the Root outlives it) and destroyed in TearDown before the renderer.
        template <typename T, typename Make> static T& keep(const std::string& key, Make&& make)
        {
            renderer();
            State& s = state();
            for (const auto& [name, object] : s.kept)
                if (name == key)
                    return *static_cast<T*>(object.get());
            std::shared_ptr<T> object = std::make_shared<T>(make());
            s.kept.emplace_back(key, object);
            return *object;
        }

        void TearDown() override
        {
            State& s = state();
            while (!s.kept.empty())
                s.kept.pop_back();
            s.renderer.reset();
        }

        /// build/test-out/ogre, or ogre-<system> under another render system than GL3Plus
        /// ($TREELOD_RENDER_SYSTEM, OgreBootstrap.h), so that runs side by side keep their pictures.
        static std::string outDir()
        {
            const char* system = std::getenv("TREELOD_RENDER_SYSTEM");
            const std::string suffix = system && *system && std::string(system) != "GL3Plus" ? "-" + std::string(system) : "";
            std::string dir = std::string(TREELOD_BINARY_DIR) + "/test-out/ogre" + suffix;
            std::filesystem::create_directories(dir);
            return dir;
        }

        static std::string sourcePath(const std::string& relative)
        {
            return std::string(TREELOD_SOURCE_DIR) + "/" + relative;
        }

    private:
        struct State
        {
            std::unique_ptr<OffscreenRenderer> renderer;
            std::vector<std::pair<std::string, std::shared_ptr<void>>> kept;
        };

        static State& state()
        {
            static State s;
            return s;
        }

        /// One Ogre log per process (ctest runs test processes in parallel): named after the
        /// test that started the renderer, "ogre-Forest.drawsTrees.log", plus the process id
        /// when more than one test runs in the process.
        static std::string logName()
        {
            const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
            std::string name = test ? std::string(test->test_suite_name()) + "." + test->name() : "startup";
            if (::testing::UnitTest::GetInstance()->test_to_run_count() != 1)
                name += "." + std::to_string(::getpid());
            return "ogre-" + name + ".log";
        }
    };

    /// `images` left to right on black, as tall as the first (for the pictures left in
    /// test-out/ogre to look at).
    inline Image sideBySide(const std::vector<Image>& images)
    {
        int width = 0;
        for (const Image& i : images)
            width += i.width;
        Image out(width, images.front().height, glm::vec4(0, 0, 0, 1));
        int x0 = 0;
        for (const Image& i : images)
        {
            for (int y = 0; y < i.height && y < out.height; ++y)
                for (int x = 0; x < i.width; ++x)
                    out.at(x0 + x, y) = i.at(x, y);
            x0 += i.width;
        }
        return out;
    }

    /// Which pixels a FLIP mean is over: the whole image, or the tree's own (meanOverTree: tree
    /// pixels in either image). A mean over the frame is at most the tree's share of it; a small
    /// tree's images are compared over its pixels, so that a wrong tree can cross the bound.
    enum class FlipOver
    {
        Frame,
        Tree
    };

    /// Mean FLIP error of `b` against `a` over `over`'s pixels; 1 (and a test failure) when FLIP fails.
    inline double flipMean(const Image& a, const Image& b, FlipOver over = FlipOver::Frame)
    {
        FlipOptions options;
        options.keepErrorMap = over == FlipOver::Tree;
        Result<FlipResult> error = flip(a, b, options);
        EXPECT_TRUE(error.ok()) << (error.ok() ? "" : error.error().message());
        if (!error.ok())
            return 1.0;
        return over == FlipOver::Tree ? meanOverTree(*error, a, b) : error->mean;
    }

    /// Rec. 709 luminance of a pixel's stored (sRGB) values.
    inline double pixelLuminance(const glm::vec4& p) { return 0.2126 * p.r + 0.7152 * p.g + 0.0722 * p.b; }

    /// Mean Rec. 709 luminance of the stored (sRGB) values.
    inline double meanLuminance(const Image& image)
    {
        double sum = 0.0;
        for (const glm::vec4& p : image.pixels)
            sum += pixelLuminance(p);
        return sum / double(image.pixels.size());
    }

    /// Package bytes cached on disk as $TREELOD_TEST_OUT/<folder>/<name>@<stamp>.treelod, the
    /// stamp the test binary's modification time: read when there, else made by `bake` and
    /// written (through a per-process temp file: ctest -j), the packages of older builds of the
    /// binary removed. Empty bytes from `bake` are returned and not cached.
    /// $TREELOD_TEST_PACKAGES, when set, is another tree's test-out folder whose packages were
    /// baked from these sources (tests/run.sh: the ASan stage reads the Release stage's, so its
    /// Ogre tests check the Ogre half and not the bakers again, which its core tests run); a
    /// package found there is used and not copied.
    inline std::vector<std::uint8_t> cachedPackage(const std::string& folder, const std::string& name,
                                                   const std::function<std::vector<std::uint8_t>()>& bake)
    {
        const auto isPackageOf = [&name](const std::filesystem::path& file) {
            return file.filename().string().rfind(name + "@", 0) == 0 && file.extension() == ".treelod";
        };
        const auto readAll = [](const std::filesystem::path& file) {
            std::vector<std::uint8_t> bytes;
            if (std::ifstream in{file, std::ios::binary})
                bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
            return bytes;
        };
        if (const char* shared = std::getenv("TREELOD_TEST_PACKAGES"); shared && *shared)
        {
            std::error_code error;
            for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::path(shared) / folder, error))
                if (isPackageOf(entry.path()))
                    if (std::vector<std::uint8_t> bytes = readAll(entry.path()); !bytes.empty())
                        return bytes;
        }
        const char* out = std::getenv("TREELOD_TEST_OUT");
        const std::filesystem::path dir =
            (out && *out ? std::string(out) : std::string(TREELOD_BINARY_DIR) + "/test-out") + "/" + folder;
        std::filesystem::create_directories(dir);
        std::error_code error;
        const auto stamp = std::filesystem::last_write_time("/proc/self/exe", error).time_since_epoch().count();
        const std::filesystem::path path = dir / (name + "@" + std::to_string(error ? 0 : stamp) + ".treelod");
        std::vector<std::uint8_t> bytes = readAll(path);
        if (!bytes.empty())
            return bytes;
        bytes = bake();
        if (bytes.empty())
            return bytes;
        for (const auto& entry : std::filesystem::directory_iterator(dir))
            if (isPackageOf(entry.path()))
                std::filesystem::remove(entry.path());
        const std::string temp = path.string() + "." + std::to_string(::getpid()) + ".tmp";
        std::ofstream(temp, std::ios::binary)
            .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
        std::filesystem::rename(temp, path);
        return bytes;
    }

    /// A fresh object of `technique` (TechniqueRegistry) for `asset` in a scene node at `at` under
    /// the content node; the content is cleared first, shadows off, the LoD bias 1.
    inline Ogre::MovableObject* placeTechnique(const std::string& technique, TreeAsset& asset,
                                               const Ogre::NameValuePairList& params = {},
                                               const Ogre::Vector3& at = Ogre::Vector3::ZERO)
    {
        static int serial = 0;
        OffscreenRenderer& r = OgreEnvironment::renderer();
        r.clearContent();
        r.setShadows(false);
        r.setLodBias(1.0f);
        Ogre::MovableObject* object = TechniqueRegistry::getSingleton().createInstance(
            technique, r.getSceneManager(), technique + "-" + std::to_string(serial++), asset, params);
        r.getContentNode().createChildSceneNode(at)->attachObject(object);
        return object;
    }

    /// Query flags: with flags 0x4, `object` is found by a ray query along `ray` with mask 0x4
    /// and not with mask 0x8.
    inline void expectRayQueryHonoursFlags(Ogre::SceneManager& sm, Ogre::MovableObject* object, const Ogre::Ray& ray)
    {
        object->setQueryFlags(0x4);
        Ogre::RaySceneQuery* query = sm.createRayQuery(ray, 0x4);
        bool found = false;
        for (const Ogre::RaySceneQueryResultEntry& hit : query->execute())
            found |= hit.movable == object;
        EXPECT_TRUE(found);
        query->setQueryMask(0x8);
        for (const Ogre::RaySceneQueryResultEntry& hit : query->execute())
            EXPECT_NE(hit.movable, object);
        sm.destroyQuery(query);
    }

    // Golden images: each render is compared with NAME.png in its golden folder by FLIP, its mean over the
    // tree's own pixels (what differs from the sky in either image, meanOverTree) below the bound
    // stated per test, so that a small tree's picture is judged where it is; with
    // TREELOD_GOLDEN=update the goldens are rewritten
    // instead (then open them and look before committing). On a failure the render and the
    // FLIP heat map are left in build/test-out/ogre/ for inspection.

    // treeCoverage (TreeViews.h): a black, empty or background-only picture cannot pass a golden test.

    /// Pixels both images cover (differ from the background) over the pixels either covers; 0
    /// when neither covers any.
    inline double coveredOverlap(const Image& a, const Image& b, const glm::vec3& background)
    {
        std::size_t both = 0, either = 0;
        for (std::size_t i = 0; i < a.pixels.size() && i < b.pixels.size(); ++i)
        {
            const bool inA = isTreePixel(a.pixels[i], background);
            const bool inB = isTreePixel(b.pixels[i], background);
            both += inA && inB;
            either += inA || inB;
        }
        return either ? double(both) / double(either) : 0.0;
    }

    /// `actual` against the golden image `golden` (a path), FLIP mean over the tree's pixels below
    /// `bound`; written to the output folder as NAME.png (and NAME.flip.png when it fails).
    /// TREELOD_GOLDEN=update rewrites the golden instead.
    inline void compareWithGoldenFile(const Image& actual, const std::string& golden, const std::string& name,
                                      double bound)
    {
        const std::string actualPath = OgreEnvironment::outDir() + "/" + name + ".png";
        ASSERT_TRUE(writePng(actualPath, actual).ok());
        const char* mode = std::getenv("TREELOD_GOLDEN");
        if (mode && std::string(mode) == "update")
        {
            ASSERT_TRUE(writePng(golden, actual).ok());
            GTEST_SKIP() << "golden updated: " << golden << " (open it and look before committing)";
        }
        Result<Image> expected = readImage(golden);
        ASSERT_TRUE(expected.ok()) << expected.error().message()
                                   << " (run with TREELOD_GOLDEN=update to create it)";
        FlipOptions options;
        options.keepErrorMap = true;
        Result<FlipResult> flipped = flip(expected.value(), actual, options);
        ASSERT_TRUE(flipped.ok()) << flipped.error().message();
        const double mean = meanOverTree(flipped.value(), expected.value(), actual);
        if (mean >= bound)
            writePng(OgreEnvironment::outDir() + "/" + name + ".flip.png", flipHeatmap(flipped.value()));
        EXPECT_LT(mean, bound) << name << " (over the tree's pixels): see " << actualPath;
    }

    /// compareWithGoldenFile with NAME.png in the calling test source's golden folder: `golden/`
    /// beside the folder the source is in (techniques/<name>/golden for techniques/<name>/tests/,
    /// tests/golden for tests/ogre/ and tests/browser/).
    inline void compareWithGolden(const Image& actual, const std::string& name, double bound,
                                  const char* caller = __builtin_FILE())
    {
        // __builtin_FILE() is relative to the source tree (-fmacro-prefix-map, CMakeLists.txt) for
        // the project's sources, absolute for others.
        const std::filesystem::path folder = std::filesystem::path(caller).parent_path().parent_path() / "golden";
        const std::string golden = (folder / (name + ".png")).string();
        compareWithGoldenFile(actual, folder.is_absolute() ? golden : OgreEnvironment::sourcePath(golden), name, bound);
    }

    /// A tree object's Entity-style mesh LoD bias, seen through callbacks: set it, read the
    /// detail index it draws for the last camera (0 = finest), render a view.
    struct MeshLodBiasProbe
    {
        std::function<void(Ogre::Real factor, unsigned short maxDetailIndex, unsigned short minDetailIndex)> setBias;
        std::function<unsigned()> index;
        std::function<void(const CameraSpec& view)> render;
        unsigned indexCount = 0; ///< detail indices the object has
    };

    /// setMeshLodBias as Entity's: at the first of `views` whose index L lies strictly between
    /// the finest and the coarsest, factor 4 draws a finer index and 0.25 a coarser one (at
    /// least one of them strictly); a camera LoD bias of 4 (Camera::setLodBias, through the
    /// strategy) draws what factor 4 draws; maxDetailIndex and minDetailIndex clamp.
    inline void expectMeshLodBiasLikeEntity(const MeshLodBiasProbe& p, const std::vector<CameraSpec>& views)
    {
        OffscreenRenderer& r = OgreEnvironment::renderer();
        ASSERT_GE(p.indexCount, 3u);
        p.setBias(1.0f, 0, 99);
        const CameraSpec* middle = nullptr;
        unsigned level = 0;
        for (const CameraSpec& view : views)
        {
            p.render(view);
            level = p.index();
            if (level > 0 && level + 1 < p.indexCount)
            {
                middle = &view;
                break;
            }
        }
        ASSERT_NE(middle, nullptr) << "no view draws a middle level";
        p.setBias(4.0f, 0, 99);
        p.render(*middle);
        const unsigned finer = p.index();
        p.setBias(0.25f, 0, 99);
        p.render(*middle);
        const unsigned coarser = p.index();
        std::printf("detail index %u; with factor 4: %u, 0.25: %u\n", level, finer, coarser);
        EXPECT_LE(finer, level);
        EXPECT_GE(coarser, level);
        EXPECT_LT(finer, coarser);

        p.setBias(1.0f, 0, 99);
        r.setLodBias(4.0f);
        p.render(*middle);
        r.setLodBias(1.0f);
        EXPECT_EQ(p.index(), finer) << "the camera's LoD bias 4 acts as factor 4";

        // Limits: a huge factor stops at maxDetailIndex, a tiny one at minDetailIndex.
        p.setBias(1e4f, 1, 99);
        p.render(*middle);
        EXPECT_EQ(p.index(), 1u);
        p.setBias(1e-4f, 0, 1);
        p.render(*middle);
        EXPECT_EQ(p.index(), 1u);
        p.setBias(1e-4f, 0, 99);
        p.render(*middle);
        EXPECT_EQ(p.index(), p.indexCount - 1);
        p.setBias(1.0f, 0, 99);
    }

    /// The lodStrategy parameter (ObjectLodBias.h) as a tree object reads it: `make(params)`
    /// places a new object with `params` (the last one gone), `index()` is what it draws for the
    /// last camera (0 = finest; LoDF: its leaf count, compared within `slack`). At each of `views`
    /// (receding), pixel_count (Ogre's: a quarter of treelod_screen_size) draws what the default
    /// draws, and still does under a camera LoD bias of 4, which Ogre's pixel_count leaves out
    /// and the default does not; distance_box (the distance to the box, shorter than to the
    /// centre) draws as fine or finer, never finer as the views recede; an unknown name is refused.
    inline void expectLodStrategyParameter(const std::function<void(const Ogre::NameValuePairList&)>& make,
                                           const std::function<unsigned()>& index,
                                           const std::function<void(const CameraSpec&)>& render,
                                           const std::vector<CameraSpec>& views, bool finerIsMore = false,
                                           unsigned slack = 0)
    {
        OffscreenRenderer& r = OgreEnvironment::renderer();
        auto indices = [&](const char* strategy, float cameraBias) {
            make(strategy ? Ogre::NameValuePairList{{"lodStrategy", strategy}} : Ogre::NameValuePairList{});
            r.setLodBias(cameraBias);
            std::vector<unsigned> out;
            for (const CameraSpec& view : views)
            {
                render(view);
                out.push_back(index());
            }
            r.setLodBias(1.0f);
            return out;
        };
        const std::vector<unsigned> byDefault = indices(nullptr, 1.0f), pixelCount = indices("pixel_count", 1.0f),
                                    distance = indices("distance_box", 1.0f), biased = indices(nullptr, 4.0f),
                                    pixelCountBiased = indices("pixel_count", 4.0f);
        auto finer = [&](unsigned a, unsigned b) { return finerIsMore ? a >= b : a <= b; }; // a as fine as b or finer
        for (std::size_t i = 0; i < views.size(); ++i)
        {
            std::printf("view %zu: default %u, pixel_count %u, distance_box %u; camera bias 4: default %u, "
                        "pixel_count %u\n", i, byDefault[i], pixelCount[i], distance[i], biased[i], pixelCountBiased[i]);
            EXPECT_NEAR(double(pixelCount[i]), double(byDefault[i]), double(slack)) << "view " << i;
            EXPECT_NEAR(double(pixelCountBiased[i]), double(byDefault[i]), double(slack))
                << "view " << i << ": Ogre's pixel_count leaves the camera's bias out";
            EXPECT_TRUE(finer(distance[i], byDefault[i])) << "view " << i;
            if (i > 0)
            {
                EXPECT_TRUE(finer(distance[i - 1], distance[i])) << "view " << i;
            }
        }
        EXPECT_NE(biased, byDefault) << "treelod_screen_size has the camera's bias";
        EXPECT_THROW(make({{"lodStrategy", "nearest"}}), Ogre::InvalidParametersException);
    }
}
