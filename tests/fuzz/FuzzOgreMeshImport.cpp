// libFuzzer target: importOgreMesh on arbitrary bytes, written to fuzz.mesh in a folder made once
// per process and rewritten per input. Ogre runs headless: a Root with no render system and no
// plugins, its buffers from DefaultHardwareBufferManager (system memory). The importer checks the
// file's chunk structure before Ogre's MeshSerializer reads it (MeshFileCheck in
// OgreMeshImporter.cpp), so no input may crash, hang, leak, read out of bounds or make Ogre
// allocate more than a small multiple of the input; a refused file is an error naming fuzz.mesh,
// and what the importer accepts must pass TreeModel::validate().
// Seeds: tests/fuzz/corpus/ogremesh/ (files Ogre 1.12's MeshSerializer wrote, see
// OgreMeshImport.checkAcceptsEveryChunkOgreWrites in tests/ogre/OgreMeshImportTest.cpp).
// Run: FuzzOgreMeshImport -max_total_time=30 corpus/ogremesh
#include "TreeLod/OgreMeshImporter.h"

#include <OgreDefaultHardwareBufferManager.h>
#include <OgreLogManager.h>
#include <OgreRoot.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include <unistd.h>

namespace
{
    namespace fs = std::filesystem;

    /// Ogre's managers without a render system, and the folder for the input file.
    struct Headless
    {
        fs::path dir;
        std::string mesh;
        Ogre::LogManager logs;
        std::unique_ptr<Ogre::Root> root;
        std::unique_ptr<Ogre::DefaultHardwareBufferManager> buffers;

        Headless()
        {
            std::string pattern = (fs::temp_directory_path() / "treelod-fuzz-mesh-XXXXXX").string();
            if (!mkdtemp(pattern.data()))
                std::abort();
            dir = pattern;
            mesh = (dir / "fuzz.mesh").string();
            logs.createLog("fuzz.log", true, false, true); // no console, no file
            root = std::make_unique<Ogre::Root>("", "", "");
            buffers = std::make_unique<Ogre::DefaultHardwareBufferManager>();
        }

        ~Headless()
        {
            buffers.reset();
            root.reset();
            std::error_code ec;
            fs::remove_all(dir, ec);
        }
    };
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    static Headless ogre;
    {
        std::ofstream out(ogre.mesh, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
        if (!out)
            std::abort();
    }
    TreeLod::Result<TreeLod::TreeModel> model = TreeLod::importOgreMesh(ogre.mesh);
    if (!model)
    {
        if (model.error().file != ogre.mesh)
            std::abort(); // errors name the file
        return 0;
    }
    if (!model->validate())
        std::abort(); // the importer promises a valid model
    return 0;
}
