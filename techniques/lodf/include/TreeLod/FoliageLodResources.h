// FoliageLodResources: LoDF (Rebollo et al. 2006) for one TreeAsset on the GPU, shared by every
// FoliageLodTree and Forest level drawing it: the decoded chunk "lodf" (checked against the
// reference), the reference's leaf vertices uploaded once, and the shared quantised levels.
#pragma once

#include "TreeLod/FoliageLodData.h"
#include "TreeLod/TechniqueResources.h"

#include <OgreHardwareIndexBuffer.h>
#include <OgreVertexIndexData.h>

#include <map>
#include <memory>
#include <vector>

namespace TreeLod
{
    class TreeAsset;

    /// One LoDF level shared by every quantised FoliageLodTree of an asset: the active leaves'
    /// indices packed (no padding), one range per run of same-material clusters, in the order
    /// of FoliageLodTree's leaf parts. Built once, never rewritten: instances switch between
    /// levels by pointing at another one, so they upload nothing and can be instanced.
    struct FoliageLodLevel
    {
        Ogre::HardwareIndexBufferSharedPtr buffer;
        std::vector<std::pair<std::size_t, std::size_t>> ranges; ///< (start, count) per leaf part
    };

    class FoliageLodResources : public TechniqueResources
    {
    public:
        /// The asset's (made on first call).
        static FoliageLodResources& of(TreeAsset& asset);

        explicit FoliageLodResources(TreeAsset& asset);
        ~FoliageLodResources() override;

        /// The LoDF foliage of chunk "lodf" (decoded on first call, checked against the
        /// reference). Its indices are renumbered to address getLeafVertexData().
        const FoliageLodData& getFoliageLod();
        /// The reference chunk's leaf vertices on the GPU, once for every instance, in the
        /// order the LoDF clusters first use them.
        Ogre::VertexData* getLeafVertexData();
        /// The shared LoDF level with `leafCount` leaves (clamped), built on first use.
        const FoliageLodLevel& getFoliageLodLevel(std::uint32_t leafCount);
        /// Shared levels built so far, and the bytes they take on the GPU.
        std::size_t getFoliageLodLevelCount() const { return mLevels.size(); }
        std::uint64_t getFoliageLodLevelBytes() const;

        std::uint64_t getGpuBytes() const override;

    private:
        TreeAsset& mAsset;
        std::unique_ptr<FoliageLodData> mData;
        std::unique_ptr<Ogre::VertexData> mLeafVertexData;
        std::vector<std::uint32_t> mLeafVertexOrder; ///< GPU vertex i = reference leaf vertex mLeafVertexOrder[i]
        std::map<std::uint32_t, FoliageLodLevel> mLevels;
    };
}
