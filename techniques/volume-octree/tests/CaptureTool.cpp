// The capture CLI test's helper (techniques/volume-octree/tests/volume-capture.sh):
//   treelod_test_capture write TREE.glb FOLDER CAMERAS RESOLUTION
//     photographs the tree with the reference renderer (synthesiseCaptureSet, one sample per
//     pixel) and writes the capture folder (writeCaptureSet);
//   treelod_test_capture coverage IMAGE.png
//     prints the fraction of pixels that differ from the top-left one (the background) by more
//     than 2/255 in some channel.
// Errors go to stderr as "file: element: reason", exit code 2.
#include "TreeLod/BakeCache.h"
#include "TreeLod/CaptureSet.h"
#include "TreeLod/Image.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>

using namespace TreeLod;

namespace
{
    int failed(const Error& error)
    {
        std::fprintf(stderr, "treelod_test_capture: %s\n", error.message().c_str());
        return 2;
    }

    int write(const std::string& tree, const std::string& folder, int cameras, int resolution)
    {
        Result<TreeModel> model = importTreeFile(tree, {}, {});
        if (!model)
            return failed(model.error());
        CaptureSynthesisOptions options;
        options.cameraCount = cameras;
        options.resolution = resolution;
        options.samplesPerPixel = 1;
        Result<CaptureSet> set = synthesiseCaptureSet(model.value(), options, tree);
        if (!set)
            return failed(set.error());
        if (Result<void> written = writeCaptureSet(set.value(), folder); !written)
            return failed(written.error());
        return 0;
    }

    int coverage(const std::string& path)
    {
        Result<Image> image = readImage(path);
        if (!image)
            return failed(image.error());
        if (image->empty())
            return failed(fail(path, "", "no pixels"));
        const glm::vec4 background = image->pixels.front();
        std::size_t differing = 0;
        for (const glm::vec4& p : image->pixels)
        {
            const glm::vec4 d = glm::abs(p - background);
            if (std::max(std::max(d.r, d.g), std::max(d.b, d.a)) > 2.0f / 255.0f)
                ++differing;
        }
        std::printf("%.6f\n", double(differing) / double(image->pixels.size()));
        return 0;
    }
}

int main(int argc, char** argv)
{
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "write" && argc == 6)
        return write(argv[2], argv[3], std::atoi(argv[4]), std::atoi(argv[5]));
    if (mode == "coverage" && argc == 3)
        return coverage(argv[2]);
    std::fprintf(stderr, "usage: treelod_test_capture write TREE.glb FOLDER CAMERAS RESOLUTION\n"
                         "       treelod_test_capture coverage IMAGE.png\n");
    return 2;
}
