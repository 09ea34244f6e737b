#include "TreeLod/TreeMeshBuilder.h"

#include <MeshLodGenerator/OgreLodConfig.h>
#include <MeshLodGenerator/OgreMeshLodGenerator.h>
#include <OgreException.h>
#include <OgreHardwareBufferManager.h>
#include <OgreMeshManager.h>
#include <OgrePixelCountLodStrategy.h>
#include <OgreSubMesh.h>

#include <map>

namespace TreeLod
{
    Ogre::VertexData* makeTreeVertexData(const std::vector<Vertex>& vertices)
    {
        auto* data = new Ogre::VertexData();
        data->vertexCount = vertices.size();
        Ogre::VertexDeclaration* decl = data->vertexDeclaration;
        size_t offset = 0;
        offset += decl->addElement(0, offset, Ogre::VET_FLOAT3, Ogre::VES_POSITION).getSize();
        offset += decl->addElement(0, offset, Ogre::VET_FLOAT3, Ogre::VES_NORMAL).getSize();
        decl->addElement(0, offset, Ogre::VET_FLOAT2, Ogre::VES_TEXTURE_COORDINATES, 0);
        static_assert(sizeof(Vertex) == 8 * sizeof(float), "Vertex must be tightly packed");
        Ogre::HardwareVertexBufferSharedPtr buffer = Ogre::HardwareBufferManager::getSingleton().createVertexBuffer(
            sizeof(Vertex), vertices.size(), Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
        buffer->writeData(0, buffer->getSizeInBytes(), vertices.data(), true);
        data->vertexBufferBinding->setBinding(0, buffer);
        return data;
    }

    namespace
    {
        void fillIndexData(Ogre::IndexData* data, const std::vector<std::uint32_t>& indices, size_t vertexCount)
        {
            const bool wide = vertexCount > 65535;
            data->indexCount = indices.size();
            data->indexStart = 0;
            data->indexBuffer = Ogre::HardwareBufferManager::getSingleton().createIndexBuffer(
                wide ? Ogre::HardwareIndexBuffer::IT_32BIT : Ogre::HardwareIndexBuffer::IT_16BIT, indices.size(),
                Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
            if (wide)
                data->indexBuffer->writeData(0, data->indexBuffer->getSizeInBytes(), indices.data(), true);
            else
            {
                std::vector<std::uint16_t> narrow(indices.begin(), indices.end());
                data->indexBuffer->writeData(0, data->indexBuffer->getSizeInBytes(), narrow.data(), true);
            }
        }

        /// Vertices and indices of the triangles of one material, compacted.
        struct Part
        {
            std::uint32_t material = 0;
            std::vector<Vertex> vertices;
            std::vector<std::uint32_t> indices;
            std::vector<std::uint32_t> source; ///< bark parts: model vertex of each vertex
        };

        /// Source 1 of `data`: the AO of each vertex as a colour (ao, ao, ao, 1).
        void addAoColours(Ogre::VertexData* data, const Part& part, const std::vector<std::uint8_t>& ao)
        {
            data->vertexDeclaration->addElement(1, 0, Ogre::VET_UBYTE4_NORM, Ogre::VES_DIFFUSE);
            std::vector<std::uint8_t> colours(part.source.size() * 4, 255);
            for (std::size_t v = 0; v < part.source.size(); ++v)
                colours[4 * v] = colours[4 * v + 1] = colours[4 * v + 2] = ao[part.source[v]];
            Ogre::HardwareVertexBufferSharedPtr buffer = Ogre::HardwareBufferManager::getSingleton().createVertexBuffer(
                4, part.source.size(), Ogre::HardwareBuffer::HBU_STATIC_WRITE_ONLY);
            buffer->writeData(0, buffer->getSizeInBytes(), colours.data(), true);
            data->vertexBufferBinding->setBinding(1, buffer);
        }

        void addSubMesh(Ogre::Mesh& mesh, const Part& part, const std::vector<Ogre::String>& materialNames)
        {
            Ogre::SubMesh* sub = mesh.createSubMesh();
            sub->useSharedVertices = false;
            sub->vertexData = makeTreeVertexData(part.vertices);
            fillIndexData(sub->indexData, part.indices, part.vertices.size());
            sub->setMaterialName(materialNames[part.material], mesh.getGroup());
        }

        std::vector<Part> barkParts(const TreeModel& model)
        {
            std::map<std::uint32_t, Part> parts; // ordered by material: deterministic submesh order
            std::vector<std::uint32_t> remap(model.barkVertices.size());
            std::vector<std::uint32_t> stamp(model.barkVertices.size(), ~0u);
            for (std::size_t t = 0; t < model.barkTriangleCount(); ++t)
            {
                std::uint32_t m = model.barkTriangleMaterial[t];
                Part& part = parts[m];
                part.material = m;
                for (int k = 0; k < 3; ++k)
                {
                    std::uint32_t v = model.barkIndices[3 * t + k];
                    if (stamp[v] != m)
                    {
                        stamp[v] = m;
                        remap[v] = std::uint32_t(part.vertices.size());
                        part.vertices.push_back(model.barkVertices[v]);
                        part.source.push_back(v);
                    }
                    part.indices.push_back(remap[v]);
                }
            }
            std::vector<Part> out;
            for (auto& kv : parts)
                out.push_back(std::move(kv.second));
            return out;
        }

        std::vector<Part> leafParts(const TreeModel& model)
        {
            std::map<std::uint32_t, Part> parts;
            for (const Leaf& leaf : model.leaves)
            {
                Part& part = parts[leaf.material];
                part.material = leaf.material;
                const std::uint32_t base = std::uint32_t(part.vertices.size());
                part.vertices.insert(part.vertices.end(), model.leafVertices.begin() + leaf.firstVertex,
                                     model.leafVertices.begin() + leaf.firstVertex + leaf.vertexCount);
                for (std::uint32_t k = 0; k < leaf.indexCount; ++k)
                    part.indices.push_back(base + model.leafIndices[leaf.firstIndex + k] - leaf.firstVertex);
            }
            std::vector<Part> out;
            for (auto& kv : parts)
                out.push_back(std::move(kv.second));
            return out;
        }
    }

    Ogre::MeshPtr buildTreeMesh(const Ogre::String& name, const Ogre::String& group, const TreeModel& model,
                                const std::vector<Ogre::String>& materialNames, const MeshBuildOptions& options)
    {
        if (materialNames.size() != model.materials.size())
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                        "mesh '" + name + "': " + std::to_string(materialNames.size()) + " material names for " +
                            std::to_string(model.materials.size()) + " materials",
                        "buildTreeMesh");
        Result<void> valid = model.validate(name);
        if (!valid)
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS, valid.error().message(), "buildTreeMesh");

        if (!options.barkVertexAo.empty() && options.barkVertexAo.size() != model.barkVertices.size())
            OGRE_EXCEPT(Ogre::Exception::ERR_INVALIDPARAMS,
                        "mesh '" + name + "': " + std::to_string(options.barkVertexAo.size()) + " AO values for " +
                            std::to_string(model.barkVertices.size()) + " bark vertices",
                        "buildTreeMesh");

        Ogre::MeshPtr mesh = Ogre::MeshManager::getSingleton().createManual(name, group);
        std::vector<Part> bark = barkParts(model);
        for (const Part& part : bark)
        {
            addSubMesh(*mesh, part, materialNames);
            if (!options.barkVertexAo.empty())
                addAoColours(mesh->getSubMesh(mesh->getNumSubMeshes() - 1)->vertexData, part, options.barkVertexAo);
        }

        Ogre::AxisAlignedBox box(model.boundsMin.x, model.boundsMin.y, model.boundsMin.z, model.boundsMax.x,
                                 model.boundsMax.y, model.boundsMax.z);
        mesh->_setBounds(box);

        // García et al. 2007 §6 (Hoppe's progressive meshes for the trunk): MeshLodGenerator on the
        // bark alone, before the leaf submeshes exist.
        if (options.barkLodLevels > 0 && !bark.empty() && Ogre::MeshLodGenerator::getSingletonPtr())
        {
            Ogre::LodConfig config(mesh, Ogre::AbsolutePixelCountLodStrategy::getSingletonPtr());
            config.advanced.useBackgroundQueue = false;
            config.advanced.useCompression = false;
            float pixels = options.firstLodPixels;
            for (unsigned level = 1; level <= options.barkLodLevels; ++level)
            {
                float reduction = 1.0f - std::pow(1.0f - options.lodReduction, float(level));
                config.createGeneratedLodLevel(pixels, reduction, Ogre::LodLevel::VRM_PROPORTIONAL);
                pixels *= options.lodPixelRatio;
            }
            Ogre::MeshLodGenerator::getSingleton().generateLodLevels(config);
        }

        // Leaves: the same full index list at every bark level.
        const unsigned short lodCount = mesh->getNumLodLevels();
        for (const Part& part : leafParts(model))
        {
            addSubMesh(*mesh, part, materialNames);
            Ogre::SubMesh* sub = mesh->getSubMesh(mesh->getNumSubMeshes() - 1);
            for (unsigned short level = 1; level < lodCount; ++level)
                sub->mLodFaceList.push_back(sub->indexData->clone(false));
        }
        mesh->_setBounds(box);
        mesh->load();
        return mesh;
    }
}
