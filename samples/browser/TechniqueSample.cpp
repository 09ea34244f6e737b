#include "TechniqueSample.h"

#include "TreeLod/TechniqueRegistry.h"

namespace TreeLod
{
    TechniqueSample::TechniqueSample(std::shared_ptr<SingleTreeView> view, std::string technique)
        : mView(std::move(view)), mTechnique(std::move(technique))
    {
    }

    std::string TechniqueSample::getTitle() const { return mTechnique; }

    std::string TechniqueSample::getDescription() const
    {
        const TechniqueInfo* info = TechniqueRegistry::getSingleton().find(mTechnique);
        const std::string source = mView->getSource().substr(mView->getSource().find_last_of('/') + 1);
        return "Technique " + mTechnique + ": " + (info ? info->description : mTechnique) + ".\n\nSplit view of " + source +
               ": the polygonal reference, the technique, and their FLIP difference (recomputed when the "
               "camera stops). Drag to orbit, wheel to zoom.";
    }

    void TechniqueSample::build(const ProgressCallback& progress) { mView->build(progress); }

    void TechniqueSample::renderThumbnail(Ogre::RenderTarget& target) { mView->renderThumbnail(mTechnique, target); }

    void TechniqueSample::attach(Ogre::RenderTarget& target, const PixelRect& area, int firstZOrder)
    {
        mView->showTechnique(mTechnique);
        mView->attach(target, area, firstZOrder);
    }

    void TechniqueSample::detach() { mView->detach(); }

    void TechniqueSample::frame(double seconds) { mView->frame(seconds); }

    std::vector<std::string> TechniqueSample::getTechniques() const
    {
        std::vector<std::string> names;
        for (const TechniqueInfo& info : TechniqueRegistry::getSingleton().getTechniques())
            names.push_back(info.name);
        return names;
    }

    void TechniqueSample::setTechnique(const std::string& technique) { mView->showTechnique(technique); }

    void TechniqueSample::setScreenshotView(unsigned, unsigned) { mView->resetView(); }
}
