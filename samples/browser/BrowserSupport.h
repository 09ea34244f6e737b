// Small helpers shared by the sample browser's samples.
#pragma once

#include "TreeLod/Camera.h"

#include <Ogre.h>

#include <cstdint>
#include <string>

namespace TreeLod
{
    /// Visibility flags of the split view: the reference draws in the left panel, the technique in
    /// the middle one (shadow cameras inherit the viewport's mask, so each casts only its own).
    constexpr Ogre::uint32 REFERENCE_VISIBILITY = 1u << 0;
    constexpr Ogre::uint32 TECHNIQUE_VISIBILITY = 1u << 1;

    /// The resource group of TreeLod's materials and assets (as OffscreenRenderer and ForestScene).
    extern const char* const TREELOD_GROUP;

    /// A rectangle of a render target in pixels.
    struct PixelRect
    {
        int left = 0, top = 0, width = 0, height = 0;
    };

    /// Put `camera` (attached to `node`) where `spec` says: position, look-at, up, field of view,
    /// clip distances; the aspect ratio is the viewport's business.
    void applyCameraSpec(Ogre::Camera& camera, Ogre::SceneNode& node, const CameraSpec& spec);

    /// Add a viewport for `camera` covering `rect` of `target` at `zOrder`.
    Ogre::Viewport* addViewport(Ogre::RenderTarget& target, Ogre::Camera* camera, int zOrder, const PixelRect& rect);

    /// GPU bytes of what `object` can draw: the vertex and index buffers of its renderables and
    /// the textures of their materials, each buffer and texture counted once.
    std::uint64_t gpuBytesOf(Ogre::MovableObject& object);

    /// "12.3 MB", "640 kB", "512 B" (powers of 1000).
    std::string formatBytes(std::uint64_t bytes);
    /// "1.23 M", "45.6 k", "789".
    std::string formatCount(double count);
    /// A bar of `cells` characters, `fraction` (0..1) of them '|' and the rest '.'.
    std::string textBar(double fraction, int cells);
}
