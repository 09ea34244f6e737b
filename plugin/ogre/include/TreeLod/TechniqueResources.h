// TechniqueResources: what one technique builds on the GPU for one TreeAsset (buffers, textures,
// materials, meshes), owned by the asset (TreeAsset::getResources) and shared by every object
// that draws the asset with that technique, single trees and Forest levels alike.
//
// Contract: built on first use, by the technique's own code, from the asset's package; the
// destructor removes everything it created from Ogre's managers (the asset destroys its
// resources when it unloads, before its own reference meshes and materials); getGpuBytes counts
// what has been uploaded so far.
#pragma once

#include <cstdint>

namespace TreeLod
{
    class TechniqueResources
    {
    public:
        virtual ~TechniqueResources() = default;
        /// Bytes on the GPU: vertex and index buffers and textures with every mip level, built so far.
        virtual std::uint64_t getGpuBytes() const { return 0; }
    };
}
