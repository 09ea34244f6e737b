// Precompiled, after TreeLodStableHeaders.h, for the targets that link OgreMain
// (cmake/TreeLodStableHeaders.cmake): the OGRE headers their sources include most.
#pragma once

#include <OgreCamera.h>
#include <OgreEntity.h>
#include <OgreException.h>
#include <OgreHardwareBufferManager.h>
#include <OgreLogManager.h>
#include <OgreMaterialManager.h>
#include <OgreMesh.h>
#include <OgreMeshManager.h>
#include <OgreMovableObject.h>
#include <OgrePass.h>
#include <OgreRenderQueue.h>
#include <OgreRoot.h>
#include <OgreSceneManager.h>
#include <OgreSubMesh.h>
#include <OgreTechnique.h>
#include <OgreTextureManager.h>
