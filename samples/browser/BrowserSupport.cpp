#include "BrowserSupport.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

namespace TreeLod
{
    const char* const TREELOD_GROUP = "TreeLod";

    void applyCameraSpec(Ogre::Camera& camera, Ogre::SceneNode& node, const CameraSpec& spec)
    {
        camera.setNearClipDistance(spec.nearClip);
        camera.setFarClipDistance(spec.farClip);
        if (spec.orthographic)
        {
            camera.setProjectionType(Ogre::PT_ORTHOGRAPHIC);
            camera.setOrthoWindowHeight(spec.orthoHeight);
        }
        else
        {
            camera.setProjectionType(Ogre::PT_PERSPECTIVE);
            camera.setFOVy(Ogre::Degree(spec.fovYDegrees));
        }
        node.setPosition(spec.position.x, spec.position.y, spec.position.z);
        node.setFixedYawAxis(true, Ogre::Vector3(spec.up.x, spec.up.y, spec.up.z));
        node.lookAt(Ogre::Vector3(spec.target.x, spec.target.y, spec.target.z), Ogre::Node::TS_WORLD);
    }

    Ogre::Viewport* addViewport(Ogre::RenderTarget& target, Ogre::Camera* camera, int zOrder, const PixelRect& rect)
    {
        const float w = float(target.getWidth()), h = float(target.getHeight());
        Ogre::Viewport* vp = target.addViewport(camera, zOrder, float(rect.left) / w, float(rect.top) / h,
                                                float(rect.width) / w, float(rect.height) / h);
        if (camera)
            camera->setAspectRatio(Ogre::Real(vp->getActualWidth()) / Ogre::Real(std::max(1, vp->getActualHeight())));
        return vp;
    }

    namespace
    {
        std::uint64_t textureBytes(const Ogre::Texture& texture)
        {
            std::uint64_t bytes = 0;
            std::uint32_t w = texture.getWidth(), h = texture.getHeight(), d = texture.getDepth();
            for (std::uint32_t mip = 0; mip <= texture.getNumMipmaps(); ++mip)
            {
                bytes += Ogre::PixelUtil::getMemorySize(w, h, d, texture.getFormat());
                w = std::max(1u, w / 2);
                h = std::max(1u, h / 2);
                d = std::max(1u, d / 2);
            }
            return bytes * texture.getNumFaces();
        }

        /// Sums what each renderable's render operation and material use, once per buffer/texture.
        class GpuBytesVisitor : public Ogre::Renderable::Visitor
        {
        public:
            void visit(Ogre::Renderable* renderable, Ogre::ushort, bool, Ogre::Any*) override
            {
                Ogre::RenderOperation op;
                renderable->getRenderOperation(op);
                if (op.vertexData)
                    for (const auto& binding : op.vertexData->vertexBufferBinding->getBindings())
                        once(binding.second.get(), binding.second->getSizeInBytes());
                if (op.useIndexes && op.indexData && op.indexData->indexBuffer)
                    once(op.indexData->indexBuffer.get(), op.indexData->indexBuffer->getSizeInBytes());
                const Ogre::MaterialPtr& material = renderable->getMaterial();
                if (!material)
                    return;
                for (Ogre::Technique* technique : material->getTechniques())
                    for (Ogre::Pass* pass : technique->getPasses())
                        for (Ogre::TextureUnitState* unit : pass->getTextureUnitStates())
                            if (unit->getContentType() == Ogre::TextureUnitState::CONTENT_NAMED)
                                if (const Ogre::TexturePtr& texture = unit->_getTexturePtr())
                                    once(texture.get(), textureBytes(*texture));
            }

            std::uint64_t bytes = 0;

        private:
            void once(const void* what, std::uint64_t size)
            {
                if (what && mSeen.insert(what).second)
                    bytes += size;
            }
            std::set<const void*> mSeen;
        };
    }

    std::uint64_t gpuBytesOf(Ogre::MovableObject& object)
    {
        GpuBytesVisitor visitor;
        object.visitRenderables(&visitor);
        return visitor.bytes;
    }

    std::string formatBytes(std::uint64_t bytes)
    {
        char text[32];
        if (bytes >= 1000000)
            std::snprintf(text, sizeof text, "%.1f MB", double(bytes) / 1e6);
        else if (bytes >= 1000)
            std::snprintf(text, sizeof text, "%.0f kB", double(bytes) / 1e3);
        else
            std::snprintf(text, sizeof text, "%u B", unsigned(bytes));
        return text;
    }

    std::string formatCount(double count)
    {
        char text[32];
        if (count >= 1e6)
            std::snprintf(text, sizeof text, "%.2f M", count / 1e6);
        else if (count >= 1e4)
            std::snprintf(text, sizeof text, "%.1f k", count / 1e3);
        else
            std::snprintf(text, sizeof text, "%.0f", count);
        return text;
    }

    std::string textBar(double fraction, int cells)
    {
        const int filled = int(std::lround(std::clamp(fraction, 0.0, 1.0) * cells));
        return std::string(std::size_t(filled), '|') + std::string(std::size_t(cells - filled), '.');
    }
}
