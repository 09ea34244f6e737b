// TechniqueSample: one LoD technique on a single tree, as a split view (SingleTreeView, shared
// by every technique sample, so switching technique keeps the view).
#pragma once

#include "BrowserSample.h"
#include "SingleTreeView.h"

#include <memory>

namespace TreeLod
{
    class TechniqueSample : public BrowserSample
    {
    public:
        /// `technique`: a TechniqueRegistry name.
        TechniqueSample(std::shared_ptr<SingleTreeView> view, std::string technique);

        std::string getTitle() const override;
        std::string getDescription() const override;
        void build(const ProgressCallback& progress) override;
        void renderThumbnail(Ogre::RenderTarget& target) override;
        void attach(Ogre::RenderTarget& target, const PixelRect& area, int firstZOrder) override;
        void detach() override;
        void frame(double seconds) override;

        Ogre::Camera& getCamera() override { return mView->getCamera(); }
        Ogre::SceneNode& getCameraNode() override { return mView->getCameraNode(); }
        Ogre::SceneNode* getOrbitTarget() override { return &mView->getOrbitTarget(); }
        float getCameraSpeed() const override { return 2.0f * mView->getRadius(); }

        bool isSplitView() const override { return true; }
        std::vector<std::string> getTechniques() const override;
        std::string getTechnique() const override { return mTechnique; }
        void setTechnique(const std::string& technique) override;
        float getLodBias() const override { return mView->getLodBias(); }
        void setLodBias(float bias) override { mView->setLodBias(bias); }
        bool getShadows() const override { return mView->getShadows(); }
        void setShadows(bool enabled) override { mView->setShadows(enabled); }
        bool getWireframe() const override { return mView->getWireframe(); }
        void setWireframe(bool enabled) override { mView->setWireframe(enabled); }
        bool hasLodTransition() const override { return true; }
        float getLodTransition() const override { return mView->getLodTransition(); }
        void setLodTransition(float length) override { mView->setLodTransition(length); }
        bool isLodFrozen() const override { return mView->isLodFrozen(); }
        void setLodFrozen(bool frozen) override { mView->setLodFrozen(frozen); }
        void setScreenshotView(unsigned index, unsigned count) override;

        std::vector<std::pair<std::string, std::string>> getStats() override { return mView->getStats(); }
        std::vector<std::string> getLevelHistogram() override { return mView->getLevelHistogram(); }

    private:
        std::shared_ptr<SingleTreeView> mView;
        std::string mTechnique;
    };
}
