// libFuzzer target: importGltfFromMemory on arbitrary bytes (.glb or .gltf JSON, chosen by
// content). It must never crash, hang or read out of bounds, and whatever it accepts must
// pass TreeModel::validate(). No base directory: the importer reads no file.
// Seeds: tests/fuzz/corpus/gltf/. Run: FuzzGltfImporter -max_total_time=30 corpus/gltf
#include "TreeLod/GltfImporter.h"

#include <cstddef>
#include <cstdint>
#include <cstdlib>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    TreeLod::ImportReport report;
    auto model = TreeLod::importGltfFromMemory(data, size, "fuzz.glb", "", {}, &report);
    if (model && !model->validate())
        std::abort(); // the importer promises a valid model
    return 0;
}
