// OgreMeshImporter: an Ogre .mesh file -> TreeModel (MeshSerializer).
//
// Every submesh is read, with its own or the mesh's shared vertex data (POSITION,
// NORMAL if present, TEXCOORD 0 if present; float formats), 16- or 32-bit indices,
// triangle lists only (strips and fans are converted, other operations are an error).
// Submeshes whose material is a leaf material become leaves, split into connected
// components exactly as the glTF importer does (LeafExtraction.h); the rest is bark.
// Leaf materials: the names in `leafMaterials`, or, when it is empty, material names
// containing "leaf", "leaves", "foliage" or "needle" (any case).
// Textures: when the submesh's material is known to Ogre (a script was parsed) and its first
// texture unit names an image found in a resource group, that image becomes the material's
// texture; otherwise the material is untextured (a warning says which).
// Needs a running Ogre::Root (MeshManager, HardwareBufferManager).
//
// Hostile input: Ogre's MeshSerializer trusts the file (a count of 2^32 vertices is allocated,
// a short file read as garbage), so the importer first walks the file's chunks as Ogre will and
// checks every length, count, size, bool and reference against the bytes present. It reads
// formats [MeshSerializer_v1.100] and [MeshSerializer_v1.8] (older ones: upgrade them with
// OgreMeshUpgrader), as Ogre's writer lays them out. Errors name the file, the chunk by name
// and offset, and the reason: "tree.mesh: chunk M_GEOMETRY_VERTEX_BUFFER_DATA at offset 310:
// 2147483647 vertices x 12 bytes need 25769803764 bytes at offset 316, the chunk has 36".
// Ogre's own exceptions become errors too. A skeleton the file names is not loaded.
#pragma once

#include "TreeLod/Progress.h"
#include "TreeLod/TreeModel.h"

#include <string>
#include <vector>

namespace TreeLod
{
    struct OgreMeshImportOptions
    {
        std::vector<std::string> leafMaterials;
        std::vector<std::string>* warnings = nullptr; ///< optional sink for warnings
    };

    Result<TreeModel> importOgreMesh(const std::string& path, const OgreMeshImportOptions& options = {});
}
