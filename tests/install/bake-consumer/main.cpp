// bake_consumer TREE.glb: imports the tree and lists the registered bakers and chunk formats; exit 1
// when the import fails or a baker has no chunk format (a technique half not linked whole).
#include "TreeLod/BakeTechniques.h"
#include "TreeLod/GltfImporter.h"
#include "TreeLod/TechniqueDescriptor.h"

#include <cstdio>

int main(int argc, char** argv)
{
    if (argc != 2)
        return 2;
    TreeLod::Result<TreeLod::TreeModel> model = TreeLod::importGltf(argv[1]);
    if (!model)
    {
        std::fprintf(stderr, "bake_consumer: %s\n", model.error().message().c_str());
        return 1;
    }
    std::printf("bakers: %s\n", TreeLod::knownBakeTechniques().c_str());
    int missing = 0;
    for (const TreeLod::BakeTechnique& technique : TreeLod::bakeTechniques())
        if (!TreeLod::findTechniqueDescriptor(technique.name))
            std::printf("baker '%s' has no chunk format\n", technique.name), ++missing;
    return TreeLod::bakeTechniques().size() > 1 && missing == 0 ? 0 : 1;
}
