// The Forest's GPU residency (Forest.h "Residency"): levels built on first need within the
// per-frame upload budget, the fallback drawn meanwhile, and the bytes held.
#include "ForestDetail.h"

namespace TreeLod
{
    std::uint64_t Forest::getGpuBytes() const { return drawableBytes() + mInstanceBufferBytes; }

    void Forest::visitPartResources(const Part& part, const ResourceVisitor& visit)
    {
        for (const auto& binding : part.vertexData->vertexBufferBinding->getBindings())
            visit(std::shared_ptr<const void>(binding.second), binding.second->getSizeInBytes());
        visit(std::shared_ptr<const void>(part.indexData->indexBuffer), part.indexData->indexBuffer->getSizeInBytes());
        if (part.mesh)
            for (const Ogre::SubMesh* sub : part.mesh->getSubMeshes())
                for (const Ogre::IndexData* lod : sub->mLodFaceList)
                    if (lod && lod->indexBuffer)
                        visit(std::shared_ptr<const void>(lod->indexBuffer), lod->indexBuffer->getSizeInBytes());
        for (const Ogre::MaterialPtr* material : {&part.material, &part.shadowedMaterial})
            if (*material)
                for (Ogre::Technique* technique : (*material)->getTechniques())
                    for (Ogre::Pass* pass : technique->getPasses())
                        for (Ogre::TextureUnitState* unit : pass->getTextureUnitStates())
                            if (unit->getContentType() == Ogre::TextureUnitState::CONTENT_NAMED)
                                if (const Ogre::TexturePtr& texture = unit->_getTexturePtr())
                                    visit(std::shared_ptr<const void>(texture), textureBytes(*texture));
    }

    std::uint64_t Forest::drawableBytes() const
    {
        std::set<const void*> seen;
        std::uint64_t bytes = 0;
        for (const std::unique_ptr<Species>& species : mSpecies)
            for (const auto& level : species->parts)
                for (const std::unique_ptr<Part>& part : level)
                    visitPartResources(*part, [&](const std::shared_ptr<const void>& what, std::uint64_t size) {
                        if (what && seen.insert(what.get()).second)
                            bytes += size;
                    });
        return bytes;
    }

    std::vector<ForestGpuResource> Forest::getGpuResources(std::uint32_t species, std::uint32_t level) const
    {
        std::vector<ForestGpuResource> resources;
        std::set<const void*> seen;
        for (const std::unique_ptr<Part>& part : mSpecies.at(species)->parts.at(level))
            visitPartResources(*part, [&](const std::shared_ptr<const void>& what, std::uint64_t size) {
                if (what && seen.insert(what.get()).second)
                    resources.push_back(ForestGpuResource{what, size});
            });
        return resources;
    }

    std::uint32_t Forest::getResidentLevelCount() const
    {
        std::uint32_t count = 0;
        for (const std::unique_ptr<Species>& species : mSpecies)
            count += std::uint32_t(std::count(species->residency.begin(), species->residency.end(), Residency::Resident));
        return count;
    }

    // ---- residency (Forest.h) ---------------------------------------------------------------------

    void Forest::setUploadBudget(std::uint64_t bytesPerFrame) { mUploadBudget = bytesPerFrame; }

    bool Forest::isResident(std::uint32_t species, std::uint32_t level) const
    {
        return mSpecies.at(species)->residency.at(level) == Residency::Resident;
    }

    std::uint32_t Forest::getDrawnLevel(std::uint32_t species, std::uint32_t level) const
    {
        // The nearest resident level, coarser first: the last level always is (addSpecies).
        const std::vector<Residency>& residency = mSpecies.at(species)->residency;
        for (std::size_t l = level; l < residency.size(); ++l)
            if (residency[l] == Residency::Resident)
                return std::uint32_t(l);
        for (std::size_t l = std::min<std::size_t>(level, residency.size()); l-- > 0;)
            if (residency[l] == Residency::Resident)
                return std::uint32_t(l);
        return level;
    }

    std::uint64_t Forest::makeResident(std::uint32_t s, std::uint32_t l)
    {
        Species& species = *mSpecies[s];
        if (species.residency[l] == Residency::Resident || species.residency[l] == Residency::Failed)
            return 0;
        const std::uint64_t before = drawableBytes();
        try
        {
            species.parts[l] =
                buildParts(*species.asset, species.levels[l], l == 0 ? NO_UPPER : species.levels[l - 1].minPixelCount);
            species.residency[l] = Residency::Resident;
        }
        catch (const Ogre::Exception& e)
        {
            // Not fatal mid-frame: the level's trees keep drawing their fallback.
            species.parts[l].clear();
            species.residency[l] = Residency::Failed;
            Ogre::LogManager::getSingleton().logError(
                "Forest '" + mName + "' species " + std::to_string(s) + " level " + std::to_string(l) + " '" +
                species.levels[l].technique + "': " + e.getDescription() + " (its trees draw level " +
                std::to_string(getDrawnLevel(s, l)) + ")");
        }
        return drawableBytes() - before;
    }

    void Forest::makeAllResident()
    {
        for (std::uint32_t s = 0; s < mSpecies.size(); ++s)
            for (std::uint32_t l = 0; l < mSpecies[s]->levels.size(); ++l)
                makeResident(s, l);
        mUploadQueue.clear();
        mStats.pendingLevels = 0;
    }

    unsigned long Forest::currentFrame()
    {
        return Ogre::Root::getSingletonPtr() ? Ogre::Root::getSingleton().getNextFrameNumber() : 0;
    }

    void Forest::serviceUploads()
    {
        const unsigned long frame = currentFrame();
        if (frame != mUploadFrame)
        {
            mUploadFrame = frame;
            mStats.uploadedBytes = 0;
            mStats.uploadedLevels = 0;
        }
        // In the order asked for, until this frame's bytes reach the budget (a level larger than
        // the whole budget goes alone in its frame: a level is not split).
        while (!mUploadQueue.empty() && (mUploadBudget == 0 || mStats.uploadedBytes < mUploadBudget))
        {
            const auto [s, l] = mUploadQueue.front();
            mUploadQueue.pop_front();
            mStats.uploadedBytes += makeResident(s, l);
            ++mStats.uploadedLevels;
        }
        mStats.pendingLevels = std::uint32_t(mUploadQueue.size());
    }
}
