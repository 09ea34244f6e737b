// Helpers shared by the headless studies in bench/ (treelod_lodf_study, treelod_bc_study,
// treelod_corpus_study):
// formatting, image conversion and metrics, tree extents and crops, panel composition, output.
#pragma once

#include "TreeLod/AtomicFile.h"
#include "TreeLod/GltfImporter.h"
#include "TreeLod/TreeGenerator.h"
#include "TreeLod/Camera.h"
#include "TreeLod/Image.h"
#include "TreeLod/ImageMetrics.h"
#include "TreeLod/OffscreenRenderer.h"
#include "TreeLod/ReferenceRenderer.h"
#include "TreeLod/RgbaImageConversion.h"
#include "TreeLod/TreeViews.h"

#include <OgreException.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace TreeLod
{
    constexpr float STUDY_FOV_Y_DEGREES = 45.0f;
    constexpr double STUDY_PI = 3.14159265358979323846;

    /// Every failure of a study: printed as one line, exit 2.
    struct StudyError : std::runtime_error
    {
        using std::runtime_error::runtime_error;
    };

    inline std::string format(const char* fmt, ...)
    {
        va_list args, copy;
        va_start(args, fmt);
        va_copy(copy, args);
        const int n = std::vsnprintf(nullptr, 0, fmt, copy);
        va_end(copy);
        std::string out(std::size_t(std::max(n, 0)) + 1, '\0');
        std::vsnprintf(out.data(), out.size(), fmt, args);
        va_end(args);
        out.resize(std::size_t(std::max(n, 0)));
        return out;
    }

    inline double secondsSince(std::chrono::steady_clock::time_point start)
    {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }

    inline double flipMean(const Image& a, const Image& b)
    {
        Result<FlipResult> r = flip(a, b);
        if (!r)
            throw StudyError("FLIP: " + r.error().message());
        return r->mean;
    }

    /// `run()`'s exit code; a StudyError, Ogre or other exception prints one line naming the
    /// study and gives 2.
    template <typename Run> int runStudy(const char* study, Run&& run)
    {
        try
        {
            return run();
        }
        catch (const StudyError& e)
        {
            std::fprintf(stderr, "%s: %s\n", study, e.what());
        }
        catch (const Ogre::Exception& e)
        {
            std::fprintf(stderr, "%s: %s\n", study, e.getFullDescription().c_str());
        }
        catch (const std::exception& e)
        {
            std::fprintf(stderr, "%s: %s\n", study, e.what());
        }
        return 2;
    }

    /// Multi-scale RMSE (combined over the bands) of `b` against `a`.
    inline double multiScaleRmseOf(const Image& a, const Image& b)
    {
        Result<MultiScaleRmseResult> r = multiScaleRmse(a, b);
        if (!r)
            throw StudyError("multi-scale RMSE: " + r.error().message());
        return r->combined;
    }

    inline double median(std::vector<double> v)
    {
        if (v.empty())
            return 0.0;
        std::sort(v.begin(), v.end());
        const std::size_t n = v.size();
        return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    }

    /// Nearest-neighbour magnification of `crop` of `image` to size x size.
    inline Image magnify(const Image& image, const Crop& crop, int size)
    {
        Image out(size, size);
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x)
                out.at(x, y) = image.at(crop.x + x * crop.side / size, crop.y + y * crop.side / size);
        return out;
    }

    /// Rows of equally sized panels with a grey gap between them.
    inline Image composePanels(const std::vector<std::vector<const Image*>>& rows)
    {
        const int gap = 4;
        const int w = rows[0][0]->width, h = rows[0][0]->height;
        std::size_t columns = 0;
        for (const auto& row : rows)
            columns = std::max(columns, row.size());
        Image out(int(columns) * w + (int(columns) - 1) * gap, int(rows.size()) * h + (int(rows.size()) - 1) * gap,
                  glm::vec4(0.25f, 0.25f, 0.25f, 1.0f));
        for (std::size_t r = 0; r < rows.size(); ++r)
            for (std::size_t c = 0; c < rows[r].size(); ++c)
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x)
                        out.at(int(c) * (w + gap) + x, int(r) * (h + gap) + y) = rows[r][c]->at(x, y);
        return out;
    }

    inline void writeText(const std::string& path, const std::string& text)
    {
        Result<void> r = writeFileAtomic(path, std::vector<std::uint8_t>(text.begin(), text.end()));
        if (!r)
            throw StudyError(r.error().message());
    }

    inline void writeImage(const std::string& path, const Image& image)
    {
        Result<void> r = writePng(path, image);
        if (!r)
            throw StudyError(r.error().message());
    }

    /// The command as typed, the program named `study` (for the summaries).
    inline std::string studyCommandLine(const char* study, int argc, char** argv)
    {
        std::string line = study;
        for (int i = 1; i < argc; ++i)
            line += std::string(" ") + argv[i];
        return line;
    }

    struct StudyTree
    {
        std::string label;
        TreeModel model;
    };

    /// A tree spec: a .glb/.gltf path, or generated:PRESET[:LEAVES[:IMAGES[:MATERIALS[:FOLD]]]] (TreeGenerator).
    /// Throws StudyError naming the spec.
    inline StudyTree loadStudyTree(const std::string& spec)
    {
        StudyTree tree;
        if (spec.rfind("generated:", 0) == 0)
        {
            std::vector<std::string> fields;
            std::stringstream in(spec.substr(10));
            for (std::string f; std::getline(in, f, ':');)
                fields.push_back(f);
            GeneratorOptions options;
            if (fields.empty() || !parsePreset(fields[0], options.preset))
                throw StudyError("tree '" + spec +
                                 "': no preset (generated:PRESET[:LEAVES[:IMAGES[:MATERIALS[:FOLD]]]])");
            try
            {
                if (fields.size() > 1)
                    options.leafCount = std::uint32_t(std::stoul(fields[1]));
                if (fields.size() > 2)
                    options.leafImages = std::uint32_t(std::stoul(fields[2]));
                if (fields.size() > 3)
                    options.leafMaterials = std::uint32_t(std::stoul(fields[3]));
                if (fields.size() > 4)
                    options.leafFold = std::stof(fields[4]);
            }
            catch (const std::exception&)
            {
                throw StudyError("tree '" + spec + "': LEAVES, IMAGES and MATERIALS are whole numbers, FOLD degrees");
            }
            Result<TreeModel> model = generateTree(options);
            if (!model)
                throw StudyError("tree '" + spec + "': " + model.error().message());
            tree.model = std::move(model.value());
            tree.label = spec;
        }
        else
        {
            Result<TreeModel> model = importGltf(spec);
            if (!model)
                throw StudyError(model.error().message());
            tree.model = std::move(model.value());
            tree.label = std::filesystem::path(spec).filename().string();
        }
        return tree;
    }

    /// summary.md and summary.json (with "command") in `out`, and the Markdown on stdout.
    inline void writeSummary(const std::string& out, const std::string& markdown, nlohmann::json json,
                             const std::string& commandLine)
    {
        json["command"] = commandLine;
        writeText(out + "/summary.md", markdown);
        writeText(out + "/summary.json", json.dump(2) + "\n");
        std::printf("%s", markdown.c_str());
    }
}
