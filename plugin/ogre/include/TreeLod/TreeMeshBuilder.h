// TreeMeshBuilder: TreeModel -> Ogre::Mesh, the polygonal reference of every comparison.
//
// Submeshes: one per bark material, then one per leaf material, each with its own
// vertex buffer (position float3, normal float3, uv0 float2) and 16-bit indices when
// its vertices fit, 32-bit otherwise. Bark gets `barkLodLevels` MeshLodGenerator levels
// (pixel-count strategy, docs/architecture.md, "Units"); leaf submeshes keep every leaf at
// every level (the foliage LoD is the techniques' job). Optionally the bark
// carries a per-vertex ambient occlusion colour (MeshBuildOptions::barkVertexAo).
#pragma once

#include "TreeLod/TreeModel.h"

#include <OgreMesh.h>

#include <vector>

namespace TreeLod
{
    struct MeshBuildOptions
    {
        unsigned barkLodLevels = 3;        ///< 0 = no bark LoD
        float firstLodPixels = 250000.0f;  ///< screen pixels below which level 1 is used
        float lodPixelRatio = 0.25f;       ///< each next level at this fraction of the previous pixels
        float lodReduction = 0.5f;         ///< fraction of bark vertices removed per level (cumulative)
        /// Ambient occlusion per model bark vertex (0..255 = 0..1), or empty. When set, bark
        /// submeshes get a second vertex buffer with a colour element (VES_DIFFUSE, UBYTE4_NORM,
        /// ao in rgb) that the TreeLod/BarkAo materials read (García et al. 2007 §5.2).
        std::vector<std::uint8_t> barkVertexAo;
    };

    /// Vertex data over `vertices` as they are (position float3, normal float3, uv0 float2;
    /// one static buffer): the layout of every TreeLod submesh.
    Ogre::VertexData* makeTreeVertexData(const std::vector<Vertex>& vertices);

    /// Build mesh `name` in `group`; `materialNames[i]` is the Ogre material for
    /// model.materials[i]. Throws Ogre::InvalidParametersException on inconsistent input.
    Ogre::MeshPtr buildTreeMesh(const Ogre::String& name, const Ogre::String& group, const TreeModel& model,
                                const std::vector<Ogre::String>& materialNames,
                                const MeshBuildOptions& options = {});
}
