#include "TreeLod/OgreMeshImporter.h"

#include "TreeLod/AtomicFile.h"
#include "TreeLod/LeafExtraction.h"

#include <OgreDataStream.h>
#include <OgreImage.h>
#include <OgreMaterialManager.h>
#include <OgreMesh.h>
#include <OgreMeshManager.h>
#include <OgreMeshSerializer.h>
#include <OgreSubMesh.h>
#include <OgreTechnique.h>

#include <algorithm>
#include <filesystem>
#include <map>

namespace TreeLod
{
    namespace
    {
        bool isLeafName(const std::string& name, const std::vector<std::string>& rule)
        {
            if (!rule.empty())
                return std::find(rule.begin(), rule.end(), name) != rule.end();
            std::string lower = name;
            std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
            for (const char* word : {"leaf", "leaves", "foliage", "needle"})
                if (lower.find(word) != std::string::npos)
                    return true;
            return false;
        }

        /// Read one element of every vertex as floats (count components); false if absent.
        bool readElement(const Ogre::VertexData& data, Ogre::VertexElementSemantic semantic, unsigned short index,
                         int count, std::vector<float>& out, std::string& error)
        {
            const Ogre::VertexElement* e = data.vertexDeclaration->findElementBySemantic(semantic, index);
            if (!e)
                return false;
            if (Ogre::VertexElement::getBaseType(e->getType()) != Ogre::VET_FLOAT1 ||
                Ogre::VertexElement::getTypeCount(e->getType()) < count)
            {
                error = "vertex element " + std::to_string(int(semantic)) + " is not float" + std::to_string(count);
                return false;
            }
            Ogre::HardwareVertexBufferSharedPtr buffer = data.vertexBufferBinding->getBuffer(e->getSource());
            Ogre::HardwareBufferLockGuard lock(buffer, Ogre::HardwareBuffer::HBL_READ_ONLY);
            const auto* base = static_cast<const unsigned char*>(lock.pData) + data.vertexStart * buffer->getVertexSize();
            out.resize(data.vertexCount * count);
            for (size_t v = 0; v < data.vertexCount; ++v)
            {
                float* f = nullptr;
                e->baseVertexPointerToElement(const_cast<unsigned char*>(base + v * buffer->getVertexSize()), &f);
                std::copy(f, f + count, &out[v * count]);
            }
            return true;
        }

        Result<std::vector<std::uint32_t>> readTriangles(const Ogre::IndexData& indexData,
                                                         Ogre::RenderOperation::OperationType op, size_t vertexCount,
                                                         const std::string& file, const std::string& element)
        {
            std::vector<std::uint32_t> raw;
            if (indexData.indexBuffer && indexData.indexCount > 0)
            {
                Ogre::HardwareIndexBufferSharedPtr ib = indexData.indexBuffer;
                Ogre::HardwareBufferLockGuard lock(ib, Ogre::HardwareBuffer::HBL_READ_ONLY);
                raw.resize(indexData.indexCount);
                for (size_t i = 0; i < indexData.indexCount; ++i)
                    raw[i] = ib->getType() == Ogre::HardwareIndexBuffer::IT_32BIT
                                 ? static_cast<const std::uint32_t*>(lock.pData)[indexData.indexStart + i]
                                 : static_cast<const std::uint16_t*>(lock.pData)[indexData.indexStart + i];
            }
            else
            {
                raw.resize(vertexCount);
                for (size_t i = 0; i < vertexCount; ++i)
                    raw[i] = std::uint32_t(i);
            }
            for (std::uint32_t i : raw)
                if (i >= vertexCount)
                    return fail(file, element, "index " + std::to_string(i) + " out of range (" +
                                                   std::to_string(vertexCount) + " vertices)");
            std::vector<std::uint32_t> tris;
            switch (op)
            {
            case Ogre::RenderOperation::OT_TRIANGLE_LIST:
                tris.assign(raw.begin(), raw.end() - raw.size() % 3);
                break;
            case Ogre::RenderOperation::OT_TRIANGLE_STRIP:
                for (size_t i = 2; i < raw.size(); ++i)
                    (i % 2 == 0) ? tris.insert(tris.end(), {raw[i - 2], raw[i - 1], raw[i]})
                                 : tris.insert(tris.end(), {raw[i - 1], raw[i - 2], raw[i]});
                break;
            case Ogre::RenderOperation::OT_TRIANGLE_FAN:
                for (size_t i = 2; i < raw.size(); ++i)
                    tris.insert(tris.end(), {raw[0], raw[i - 1], raw[i]});
                break;
            default:
                return fail(file, element, "operation type " + std::to_string(int(op)) + " is not triangles");
            }
            return tris;
        }

        /// The first texture of a material Ogre knows, as RGBA8; false if none can be had.
        bool loadMaterialTexture(const std::string& materialName, const std::string& group, TextureImage& out)
        {
            Ogre::MaterialPtr material = Ogre::MaterialManager::getSingleton().getByName(materialName, group);
            if (!material || material->getNumTechniques() == 0)
                return false;
            Ogre::Technique* tech = material->getTechnique(0);
            if (tech->getNumPasses() == 0 || tech->getPass(0)->getNumTextureUnitStates() == 0)
                return false;
            const Ogre::String& textureName = tech->getPass(0)->getTextureUnitState(0)->getTextureName();
            if (textureName.empty())
                return false;
            try
            {
                Ogre::Image image;
                image.load(textureName, Ogre::ResourceGroupManager::AUTODETECT_RESOURCE_GROUP_NAME);
                out.name = textureName;
                out.width = int(image.getWidth());
                out.height = int(image.getHeight());
                out.rgba.resize(size_t(out.width) * out.height * 4);
                Ogre::PixelBox dst(image.getWidth(), image.getHeight(), 1, Ogre::PF_BYTE_RGBA, out.rgba.data());
                Ogre::PixelUtil::bulkPixelConversion(image.getPixelBox(), dst);
                return true;
            }
            catch (const Ogre::Exception&)
            {
                return false;
            }
        }
    }

    namespace
    {
        /// Records submesh material names as the file has them: SubMesh keeps only the
        /// names of materials Ogre knows, and a tree's scripts are often not loaded.
        struct MaterialNameRecorder : Ogre::MeshSerializerListener
        {
            std::vector<std::string> names;
            void processMaterialName(Ogre::Mesh*, Ogre::String* name) override { names.push_back(*name); }
            void processSkeletonName(Ogre::Mesh*, Ogre::String*) override {}
            void processMeshCompleted(Ogre::Mesh*) override {}
        };
    }

    Result<TreeModel> importOgreMesh(const std::string& path, const OgreMeshImportOptions& options)
    {
        Result<std::vector<std::uint8_t>> bytes = readFile(path);
        if (!bytes)
            return bytes.error();
        static int counter = 0;
        const Ogre::String meshName = "TreeLod/import/" + std::to_string(counter++) + "/" +
                                      std::filesystem::path(path).filename().string();
        Ogre::MeshPtr mesh = Ogre::MeshManager::getSingleton().createManual(meshName, Ogre::RGN_INTERNAL);
        // Shadow buffers so the data can be read back whatever the render system.
        mesh->setVertexBufferPolicy(Ogre::HardwareBuffer::HBU_STATIC, true);
        mesh->setIndexBufferPolicy(Ogre::HardwareBuffer::HBU_STATIC, true);
        // Loaded while still empty (a manual mesh without a loader loads nothing): a Mesh frees
        // its submeshes, buffers and animations when it unloads, and unloads only when loaded.
        mesh->load();
        struct Remover
        {
            Ogre::MeshPtr mesh;
            ~Remover() { Ogre::MeshManager::getSingleton().remove(mesh); }
        } remover{mesh};
        MaterialNameRecorder recorder;
        try
        {
            Ogre::DataStreamPtr stream(new Ogre::MemoryDataStream(bytes->data(), bytes->size(), false, true));
            Ogre::MeshSerializer serializer;
            serializer.setListener(&recorder);
            serializer.importMesh(stream, mesh.get());
        }
        catch (const Ogre::Exception& e)
        {
            return fail(path, "mesh", e.getDescription());
        }

        TreeModel model;
        model.name = std::filesystem::path(path).stem().string();
        std::map<std::string, std::uint32_t> materialIndex;
        detail::LeafSoup soup;
        for (unsigned short s = 0; s < mesh->getNumSubMeshes(); ++s)
        {
            Ogre::SubMesh* sub = mesh->getSubMesh(s);
            const std::string matName = s < recorder.names.size() ? recorder.names[s] : sub->getMaterialName();
            const std::string element = "submesh " + std::to_string(s) + " '" + matName + "'";
            const Ogre::VertexData* vd = sub->useSharedVertices ? mesh->sharedVertexData : sub->vertexData;
            if (!vd)
                return fail(path, element, "no vertex data");
            std::vector<float> pos, nrm, uv;
            std::string error;
            if (!readElement(*vd, Ogre::VES_POSITION, 0, 3, pos, error))
                return fail(path, element, error.empty() ? "no POSITION element" : error);
            if (!readElement(*vd, Ogre::VES_NORMAL, 0, 3, nrm, error) && !error.empty())
                return fail(path, element, error);
            if (!readElement(*vd, Ogre::VES_TEXTURE_COORDINATES, 0, 2, uv, error) && !error.empty())
                return fail(path, element, error);
            Result<std::vector<std::uint32_t>> tris =
                readTriangles(*sub->indexData, sub->operationType, vd->vertexCount, path, element);
            if (!tris)
                return tris.error();

            auto found = materialIndex.find(matName);
            if (found == materialIndex.end())
            {
                Material m;
                m.name = matName;
                m.isLeaf = isLeafName(matName, options.leafMaterials);
                m.doubleSided = m.isLeaf;
                TextureImage texture;
                if (loadMaterialTexture(matName, mesh->getGroup(), texture))
                {
                    m.texture = std::int32_t(model.textures.size());
                    model.textures.push_back(std::move(texture));
                }
                else if (options.warnings)
                    options.warnings->push_back(path + ": material '" + matName +
                                                "' has no loadable texture; imported untextured");
                found = materialIndex.emplace(matName, std::uint32_t(model.materials.size())).first;
                model.materials.push_back(m);
            }
            const std::uint32_t material = found->second;
            const bool leaf = model.materials[material].isLeaf;

            std::vector<Vertex>& target = leaf ? soup.vertices : model.barkVertices;
            const std::uint32_t base = std::uint32_t(target.size());
            for (size_t v = 0; v < vd->vertexCount; ++v)
            {
                Vertex out;
                out.position = {pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]};
                if (!std::isfinite(out.position.x) || !std::isfinite(out.position.y) || !std::isfinite(out.position.z))
                    return fail(path, element + " vertex " + std::to_string(v), "position is not finite");
                if (!nrm.empty())
                    out.normal = {nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]};
                if (!uv.empty())
                    out.uv = {uv[2 * v], uv[2 * v + 1]};
                target.push_back(out);
            }
            for (size_t i = 0; i < tris->size(); ++i)
            {
                (leaf ? soup.indices : model.barkIndices).push_back(base + (*tris)[i]);
                if (i % 3 == 0)
                    (leaf ? soup.triangleMaterial : model.barkTriangleMaterial).push_back(material);
            }
        }
        if (model.barkIndices.empty() && soup.indices.empty())
            return fail(path, "mesh", "no triangles");
        detail::extractLeaves(soup, model);
        model.updateBounds();
        Result<void> valid = model.validate(path);
        if (!valid)
            return valid.error();
        return model;
    }
}
