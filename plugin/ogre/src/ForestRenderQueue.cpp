// The Forest per camera: cull and LoD-select the instances (ForestInstances), fill each level's
// instance buffer and queue its batches; the viewer camera drives uploads and the frame budget.
#include "ForestDetail.h"

namespace TreeLod
{
    void Forest::_notifyManager(Ogre::SceneManager* manager)
    {
        if (mManager && mViewerListener)
            mManager->removeListener(mViewerListener.get());
        Ogre::MovableObject::_notifyManager(manager);
        if (!mViewerListener)
            mViewerListener = std::make_unique<ViewerListener>(*this);
        if (mManager)
            mManager->addListener(mViewerListener.get());
    }

    void Forest::clearFrameStats()
    {
        if (currentFrame() != mUploadFrame)
        {
            mStats.uploadedBytes = 0;
            mStats.uploadedLevels = 0;
        }
        mStats.fallbackInstances = 0;
        mStats.instances = std::uint32_t(mInstances.size());
        mStats.visibleInstances = 0;
        mStats.levelSwitches = 0;
        mStats.transitionInstances = 0;
        mStats.occludedInstances = 0;
        mStats.batches = 0;
        mStats.triangles = 0;
        mStats.cullMilliseconds = 0.0;
        for (std::vector<std::uint32_t>& counts : mStats.levelCounts)
            std::fill(counts.begin(), counts.end(), 0u);
    }

    void Forest::_notifyCurrentCamera(Ogre::Camera* camera)
    {
        Ogre::MovableObject::_notifyCurrentCamera(camera);
        mCurrentCamera = camera;
    }

    void Forest::fillBucket(CameraState& state, std::uint32_t b, std::uint32_t level)
    {
        const ForestBucket& bucket = state.visibility.getBucket(b);
        BucketState& slot = *state.buckets[b];
        const std::uint32_t drawn = getDrawnLevel(bucket.kind, level);
        if (slot.drawnLevel != drawn)
        {
            // First use, or the bucket's own level (or a nearer fallback) became resident.
            slot.batches.clear();
            for (const std::unique_ptr<Part>& part : mSpecies[bucket.kind]->parts[drawn])
            {
                slot.batches.push_back(std::make_unique<Batch>(*this, *part));
                if (slot.buffer)
                    slot.batches.back()->setInstanceBuffer(slot.buffer);
            }
            slot.drawnLevel = drawn;
            slot.backToFront = std::any_of(mSpecies[bucket.kind]->parts[drawn].begin(),
                                           mSpecies[bucket.kind]->parts[drawn].end(),
                                           [](const std::unique_ptr<Part>& part) { return part->backToFront; });
        }
        if (bucket.count > slot.capacity)
        {
            // Grown by doubling, never shrunk: steady frames allocate nothing.
            const std::size_t capacity =
                std::max({std::size_t(bucket.count), 2 * slot.capacity, MIN_INSTANCE_CAPACITY});
            slot.buffer = Ogre::HardwareBufferManager::getSingleton().createVertexBuffer(
                INSTANCE_BYTES, capacity, Ogre::HardwareBuffer::HBU_DYNAMIC_WRITE_ONLY_DISCARDABLE);
            slot.buffer->setIsInstanceData(true);
            slot.buffer->setInstanceDataStepRate(1);
            mInstanceBufferBytes += (capacity - slot.capacity) * INSTANCE_BYTES;
            slot.capacity = capacity;
            for (const std::unique_ptr<Batch>& batch : slot.batches)
                batch->setInstanceBuffer(slot.buffer);
        }
        // The cull's rows [R*s | t] (ForestInstances.h): t, s = m11, cos = m00 / s, sin = m02 / s.
        const float* transforms = state.visibility.getBucketTransforms(b);
        const float* codes = state.visibility.getBucketTransitionCodes(b);
        constexpr std::size_t STRIDE = ForestVisibility::TRANSFORM_FLOATS;
        if (slot.backToFront)
        {
            // Far to near: instances of one draw rasterise in order, so the blending is right
            // between the bucket's trees.
            state.depthOrder.clear();
            for (std::uint32_t i = 0; i < bucket.count; ++i)
            {
                const float* m = transforms + i * STRIDE;
                const glm::vec3 d = glm::vec3(m[3], m[7], m[11]) - state.eye;
                state.depthOrder.emplace_back(glm::dot(d, d), i);
            }
            std::sort(state.depthOrder.begin(), state.depthOrder.end(),
                      [](const auto& a, const auto& b) { return a.first > b.first; });
            slot.farthestSquared = state.depthOrder.empty() ? 0.0f : state.depthOrder.front().first;
        }
        float* out = static_cast<float*>(
            slot.buffer->lock(0, std::size_t(bucket.count) * INSTANCE_BYTES, Ogre::HardwareBuffer::HBL_DISCARD));
        for (std::uint32_t i = 0; i < bucket.count; ++i, out += INSTANCE_FLOATS)
        {
            const std::uint32_t draw = slot.backToFront ? state.depthOrder[i].second : i;
            const float* m = transforms + draw * STRIDE;
            const float scale = m[5], inverse = 1.0f / scale;
            out[0] = m[3];
            out[1] = m[7];
            out[2] = m[11];
            out[3] = scale;
            out[4] = m[0] * inverse;
            out[5] = m[2] * inverse;
            out[6] = codes[draw];
        }
        slot.buffer->unlock();
    }

    void Forest::_updateRenderQueue(Ogre::RenderQueue* queue)
    {
        if (mManager)
            notifyShadowTechnique(*mManager);
        Ogre::Camera* camera = mCurrentCamera;
        if (!camera || mSpecies.empty())
            return;
        const bool shadowTexture =
            mManager && mManager->_getCurrentRenderStage() == Ogre::SceneManager::IRS_RENDER_TO_TEXTURE;
        const bool viewer = camera->getLodCamera() == camera && !shadowTexture;
        if (const float pending = mBudget.getPendingErrorBudget(); viewer && !std::isnan(pending))
        {
            // The frame budget's choice of the last measurement, before this camera culls.
            try
            {
                applyErrorBudget(pending);
                mBudget.commitPending(true);
            }
            catch (const Ogre::Exception& e)
            {
                Ogre::LogManager::getSingleton().logError(e.getDescription());
                mBudget.commitPending(false);
            }
        }
        std::unique_ptr<CameraState>& entry = mCameras[camera];
        if (!entry)
        {
            entry = std::make_unique<CameraState>();
            camera->addListener(mCameraListener.get());
        }
        CameraState& state = *entry;
        while (state.buckets.size() < mInstances.getBucketCount()) // species added since
            state.buckets.push_back(std::make_unique<BucketState>());

        // Culling: this camera's frustum in the Forest's local space (instances are local).
        const Ogre::Affine3& world = _getParentNodeFullTransform();
        const glm::dmat4 localToClip =
            toGlm(camera->getProjectionMatrix()) * toGlm(camera->getViewMatrix()) * toGlm(world);
        state.camera.planes = CullCamera::frustumPlanes(localToClip);
        // Occlusion: the viewer's own cull only (Forest.h, setOcclusion).
        state.camera.occlusion = mOcclusion && viewer;
        state.camera.viewProjection = glm::mat4(localToClip);
        // Radii are local: the node's (uniform) scale takes them to the view's units.
        const float nodeScale = Ogre::Vector3(world[0][0], world[1][0], world[2][0]).length();
        state.camera.projectionScale = nodeScale * glm::vec2(float(camera->getProjectionMatrix()[0][0]),
                                                             float(camera->getProjectionMatrix()[1][1]));
        state.camera.viewportHeight = camera->getViewport() ? float(camera->getViewport()->getActualHeight()) : 0.0f;
        if (state.camera.occlusion)
            makeOcclusionMasks();
        // LoD: the LoD camera (the viewer's, for shadow cameras), unless frozen.
        if (!mLodFrozen || !state.hasLod)
        {
            const Ogre::Camera* lod = camera->getLodCamera();
            const Ogre::Vector3 eye = world.inverse() * lod->getDerivedPosition();
            state.camera.lodPosition = glm::vec3(eye.x, eye.y, eye.z);
            state.camera.lodPixelScale = ScreenSizeLodStrategy::pixelScale(*lod); // treelod_screen_size's
            state.camera.lodOrthographic = lod->getProjectionType() == Ogre::PT_ORTHOGRAPHIC;
            state.lodBias = lod->getLodBias() * mLodBias.meshFactor * (shadowTexture ? mShadowLodBias : 1.0f);
            state.hasLod = true;
        }
        const Ogre::Vector3 eye = world.inverse() * camera->getDerivedPosition();
        state.eye = glm::vec3(eye.x, eye.y, eye.z);

        const auto start = std::chrono::steady_clock::now();
        const Result<void> culled = mInstances.cull(state.camera, state.lodBias, state.visibility, mLodHysteresis, mLodTransition);
        const double cullMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        if (!culled)
        {
            Ogre::LogManager::getSingleton().logError("Forest '" + mName + "': " + culled.error().message());
            return;
        }
        if (viewer && mBudget.isActive() && !mLodFrozen && mBudget.countViewerFrame(FRAME_BUDGET_INTERVAL))
            measureFrameBudget(state);

        // The level each bucket draws: shadow casters their species' shadow level.
        auto wantedLevel = [&](const ForestBucket& bucket) {
            return shadowTexture ? mSpecies[bucket.kind]->shadowLevels[bucket.level] : bucket.level;
        };

        // Residency: ask for the levels this camera needs, then build within this frame's budget;
        // until built, a level's trees draw the nearest resident level (getDrawnLevel).
        for (std::uint32_t b = 0; b < state.visibility.getBucketCount(); ++b)
        {
            const ForestBucket& bucket = state.visibility.getBucket(b);
            const std::uint32_t level = wantedLevel(bucket);
            Residency& residency = mSpecies[bucket.kind]->residency[level];
            if (bucket.count > 0 && residency == Residency::Absent)
            {
                residency = Residency::Queued;
                mUploadQueue.emplace_back(bucket.kind, level);
            }
        }
        serviceUploads();

        std::uint32_t batches = 0;
        std::uint64_t triangles = 0;
        std::uint32_t fallbacks = 0;
        const Ogre::Vector4 lengthParams(0.0f, 1.0f, 0.0f, 0.0f);
        for (std::uint32_t b = 0; b < state.visibility.getBucketCount(); ++b)
        {
            const ForestBucket& bucket = state.visibility.getBucket(b);
            if (viewer)
                mStats.levelCounts[bucket.kind][bucket.level] = bucket.count;
            if (bucket.count == 0)
                continue;
            fillBucket(state, b, wantedLevel(bucket));
            if (state.buckets[b]->drawnLevel != wantedLevel(bucket))
                fallbacks += bucket.count;
            for (const std::unique_ptr<Batch>& batch : state.buckets[b]->batches)
            {
                batch->mInstanceCount = bucket.count;
                if (batch->getPart().lengthFactor > 0.0f)
                {
                    // x: the length factor, the bias applied to lengths; y: 1 (ForestLevelProvider.h).
                    Ogre::Vector4 params = lengthParams;
                    params.x = batch->getPart().lengthFactor * std::sqrt(state.lodBias);
                    batch->setCustomParameter(0, params);
                }
                // Blending draws queue at their farthest tree's depth (world units: times the
                // node's scale squared), so that Ogre sorts them back to front among transparents.
                batch->mSquaredViewDepth =
                    batch->getPart().backToFront
                        ? state.buckets[b]->farthestSquared *
                              (mParentNode ? mParentNode->_getDerivedScale().squaredLength() / 3.0f : 1.0f)
                        : -1.0f;
                queue->addRenderable(batch.get(), mRenderQueueID, mRenderQueuePriority);
                ++batches;
                triangles += std::uint64_t(batch->getPart().indexData->indexCount / 3) * bucket.count;
            }
        }
        if (viewer)
        {
            mStats.instances = std::uint32_t(mInstances.size());
            mStats.visibleInstances = state.visibility.getVisibleCount();
            mStats.levelSwitches = state.visibility.getSwitchCount();
            mStats.transitionInstances = state.visibility.getTransitionCount();
            mStats.occludedInstances = state.visibility.getOccludedCount();
            mStats.batches = batches;
            mStats.triangles = triangles;
            mStats.cullMilliseconds = cullMs;
            mStats.fallbackInstances = fallbacks;
        }
        mStats.instanceBufferBytes = mInstanceBufferBytes;
    }

    void Forest::dropCamera(Ogre::Camera* camera)
    {
        const auto found = mCameras.find(camera);
        if (found == mCameras.end())
            return;
        for (const std::unique_ptr<BucketState>& bucket : found->second->buckets)
            mInstanceBufferBytes -= bucket->capacity * INSTANCE_BYTES;
        mStats.instanceBufferBytes = mInstanceBufferBytes;
        if (mCurrentCamera == camera)
            mCurrentCamera = nullptr;
        mCameras.erase(found);
    }

    void Forest::visitRenderables(Ogre::Renderable::Visitor* visitor, bool)
    {
        for (const auto& camera : mCameras)
            for (const std::unique_ptr<BucketState>& bucket : camera.second->buckets)
                for (const std::unique_ptr<Batch>& batch : bucket->batches)
                    visitor->visit(batch.get(), 0, false);
    }

    Ogre::MovableObject* ForestFactory::createInstanceImpl(const Ogre::String& name,
                                                           const Ogre::NameValuePairList* params)
    {
        const ObjectParams p(params, "ForestFactory::createInstanceImpl");
        double bias = 1.0;
        p.number("lodBias", 1e-6, 1e6, bias);
        auto forest = std::make_unique<Forest>(name);
        forest->setLodBias(Ogre::Real(bias));
        return forest.release();
    }
}
