#include "TreeLod/OgreMeshImporter.h"

#include "TreeLod/AtomicFile.h"
#include "TreeLod/LeafExtraction.h"

#include <OgreDataStream.h>
#include <OgreImage.h>
#include <OgreMaterialManager.h>
#include <OgreMesh.h>
#include <OgreMeshFileFormat.h>
#include <OgreMeshManager.h>
#include <OgreMeshSerializer.h>
#include <OgreSubMesh.h>
#include <OgreTechnique.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

namespace TreeLod
{
    // ---- the .mesh pre-pass --------------------------------------------------------------------
    namespace
    {
        /// Internal only: thrown by MeshFileCheck, turned into a Result by importOgreMesh.
        struct MeshFileError
        {
            std::string element;
            std::string reason;
        };

        const char* chunkName(std::uint16_t id)
        {
            switch (id)
            {
            case Ogre::M_MESH: return "M_MESH";
            case Ogre::M_SUBMESH: return "M_SUBMESH";
            case Ogre::M_SUBMESH_OPERATION: return "M_SUBMESH_OPERATION";
            case Ogre::M_SUBMESH_BONE_ASSIGNMENT: return "M_SUBMESH_BONE_ASSIGNMENT";
            case Ogre::M_SUBMESH_TEXTURE_ALIAS: return "M_SUBMESH_TEXTURE_ALIAS";
            case Ogre::M_GEOMETRY: return "M_GEOMETRY";
            case Ogre::M_GEOMETRY_VERTEX_DECLARATION: return "M_GEOMETRY_VERTEX_DECLARATION";
            case Ogre::M_GEOMETRY_VERTEX_ELEMENT: return "M_GEOMETRY_VERTEX_ELEMENT";
            case Ogre::M_GEOMETRY_VERTEX_BUFFER: return "M_GEOMETRY_VERTEX_BUFFER";
            case Ogre::M_GEOMETRY_VERTEX_BUFFER_DATA: return "M_GEOMETRY_VERTEX_BUFFER_DATA";
            case Ogre::M_MESH_SKELETON_LINK: return "M_MESH_SKELETON_LINK";
            case Ogre::M_MESH_BONE_ASSIGNMENT: return "M_MESH_BONE_ASSIGNMENT";
            case Ogre::M_MESH_LOD_LEVEL: return "M_MESH_LOD_LEVEL";
            case Ogre::M_MESH_LOD_USAGE: return "M_MESH_LOD_USAGE";
            case Ogre::M_MESH_LOD_MANUAL: return "M_MESH_LOD_MANUAL";
            case Ogre::M_MESH_LOD_GENERATED: return "M_MESH_LOD_GENERATED";
            case Ogre::M_MESH_BOUNDS: return "M_MESH_BOUNDS";
            case Ogre::M_SUBMESH_NAME_TABLE: return "M_SUBMESH_NAME_TABLE";
            case Ogre::M_SUBMESH_NAME_TABLE_ELEMENT: return "M_SUBMESH_NAME_TABLE_ELEMENT";
            case Ogre::M_EDGE_LISTS: return "M_EDGE_LISTS";
            case Ogre::M_EDGE_LIST_LOD: return "M_EDGE_LIST_LOD";
            case Ogre::M_EDGE_GROUP: return "M_EDGE_GROUP";
            case Ogre::M_POSES: return "M_POSES";
            case Ogre::M_POSE: return "M_POSE";
            case Ogre::M_POSE_VERTEX: return "M_POSE_VERTEX";
            case Ogre::M_ANIMATIONS: return "M_ANIMATIONS";
            case Ogre::M_ANIMATION: return "M_ANIMATION";
            case Ogre::M_ANIMATION_BASEINFO: return "M_ANIMATION_BASEINFO";
            case Ogre::M_ANIMATION_TRACK: return "M_ANIMATION_TRACK";
            case Ogre::M_ANIMATION_MORPH_KEYFRAME: return "M_ANIMATION_MORPH_KEYFRAME";
            case Ogre::M_ANIMATION_POSE_KEYFRAME: return "M_ANIMATION_POSE_KEYFRAME";
            case Ogre::M_ANIMATION_POSE_REF: return "M_ANIMATION_POSE_REF";
            case Ogre::M_TABLE_EXTREMES: return "M_TABLE_EXTREMES";
            default: return nullptr;
            }
        }

        std::string hex16(std::uint16_t v)
        {
            const char* digits = "0123456789abcdef";
            std::string out = "0x";
            for (int shift = 12; shift >= 0; shift -= 4)
                out += digits[(v >> shift) & 0xf];
            return out;
        }

        /// Walks a .mesh file the way Ogre 1.12's MeshSerializerImpl reads formats
        /// [MeshSerializer_v1.100] and [MeshSerializer_v1.8], before Ogre does. Ogre's reader trusts
        /// the file: it allocates whatever a count says, reads past the end as garbage, indexes
        /// arrays with file values and follows chunk ids, not lengths. This check accepts only
        /// files that Ogre reads exactly as their chunk lengths nest: every chunk a kind its parent
        /// holds (in the order Ogre's writer puts them where Ogre depends on it), its length
        /// covering exactly what Ogre reads from it, every count times its size present in the
        /// chunk, every bool 0 or 1, strings ending in a line feed with no NUL, and every
        /// reference (vertex source, submesh, LOD level, pose) naming something that exists.
        class MeshFileCheck
        {
        public:
            explicit MeshFileCheck(const std::vector<std::uint8_t>& bytes) : mBytes(bytes) {}

            /// Throws MeshFileError at the first problem.
            void run()
            {
                header();
                mHeaderDone = true;
                if (mAt == mBytes.size())
                    bad("no M_MESH chunk after the header");
                if (openChunk() != Ogre::M_MESH)
                    bad("expected M_MESH (" + hex16(Ogre::M_MESH) + ") after the header");
                mesh();
                closeChunk();
                if (mAt != mBytes.size())
                    bad(std::to_string(mBytes.size() - mAt) + " bytes after the M_MESH chunk, at offset " +
                        std::to_string(mAt));
            }

        private:
            struct Chunk
            {
                std::uint16_t id;
                std::uint64_t offset, end;
            };

            struct Sub
            {
                bool shared = false;
                std::uint32_t vertices = 0; ///< its own geometry's
            };

            static constexpr std::uint64_t NO_BUFFER = ~std::uint64_t(0);

            const std::vector<std::uint8_t>& mBytes;
            std::uint64_t mAt = 0;
            bool mHeaderDone = false;
            bool mFlip = false; ///< the file's byte order is not this machine's
            bool mV18 = false;  ///< [MeshSerializer_v1.8]: LOD levels as that format has them
            std::vector<Chunk> mChunks; ///< the open chunks, outermost first

            bool mShared = false;
            std::uint32_t mSharedVertices = 0;
            std::vector<Sub> mSubs;
            bool mLod = false, mEdges = false;
            std::uint16_t mLodCount = 1;
            /// per LOD level: a manual level's mesh is another file, which owns its edge data
            std::vector<bool> mLodManual = {false};
            std::vector<bool> mEdgeLod; ///< per LOD level: has an edge list
            std::size_t mPoses = 0;
            std::set<std::string> mAnimations;

            // ---- errors and reading ----

            std::string element() const
            {
                if (mChunks.empty())
                    return mHeaderDone ? "file" : "header";
                const Chunk& c = mChunks.back();
                const char* name = chunkName(c.id);
                return "chunk " + (name ? std::string(name) : hex16(c.id)) + " at offset " + std::to_string(c.offset);
            }

            [[noreturn]] void bad(const std::string& reason) const { throw MeshFileError{element(), reason}; }

            std::uint64_t end() const { return mChunks.empty() ? mBytes.size() : mChunks.back().end; }
            std::uint64_t left() const { return end() - mAt; }

            void need(std::uint64_t bytes) const
            {
                if (bytes > left())
                    bad("truncated: needs " + std::to_string(bytes) + " bytes at offset " + std::to_string(mAt) +
                        (mChunks.empty() ? ", the file ends at " : ", the chunk ends at ") + std::to_string(end()));
            }

            /// `count` items of `size` bytes (what Ogre allocates and then reads) must be in the chunk.
            void array(std::uint64_t count, std::uint64_t size, const std::string& what)
            {
                if (count * size > left()) // counts: 32-bit fields, at most times 6; sizes < 2^17
                    bad(std::to_string(count) + " " + what + " x " + std::to_string(size) + " bytes need " +
                        std::to_string(count * size) + " bytes at offset " + std::to_string(mAt) + ", the chunk has " +
                        std::to_string(left()));
                mAt += count * size;
            }

            /// The value at `at`, which the caller has checked lies in the file.
            template <typename T> T peek(std::uint64_t at) const
            {
                T v;
                std::memcpy(&v, mBytes.data() + at, sizeof(T));
                if (mFlip)
                {
                    unsigned char* b = reinterpret_cast<unsigned char*>(&v);
                    std::reverse(b, b + sizeof(T));
                }
                return v;
            }

            template <typename T> T number()
            {
                need(sizeof(T));
                mAt += sizeof(T);
                return peek<T>(mAt - sizeof(T));
            }

            /// Ogre's writer leaves some chunks out of their parents' lengths: take `bytes` more
            /// in every open chunk, as long as the file has them.
            void widen(std::uint64_t bytes, const std::string& why)
            {
                if (mChunks.front().end + bytes > mBytes.size())
                    bad(why + ", but the file ends before");
                for (Chunk& open : mChunks)
                    open.end += bytes;
            }

            std::uint16_t u16() { return number<std::uint16_t>(); }
            std::uint32_t u32() { return number<std::uint32_t>(); }
            void floats(std::uint64_t n) { array(n, 4, "floats"); }

            bool boolean()
            {
                need(1);
                const std::uint8_t b = mBytes[std::size_t(mAt)];
                if (b > 1)
                    bad("byte " + std::to_string(b) + " at offset " + std::to_string(mAt) + " is not a bool (0 or 1)");
                ++mAt;
                return b == 1;
            }

            /// Ogre's DataStream::getLine: up to a line feed, a CR before it dropped. It scans with
            /// strchr, so a NUL before the line feed would make it read past it.
            std::string string()
            {
                const std::uint64_t start = mAt;
                for (std::uint64_t i = start; i < end(); ++i)
                {
                    const char c = char(mBytes[std::size_t(i)]);
                    if (c == '\0')
                        bad("the string at offset " + std::to_string(start) + " holds a NUL byte at offset " +
                            std::to_string(i));
                    if (c == '\n')
                    {
                        std::string text(reinterpret_cast<const char*>(mBytes.data() + start), std::size_t(i - start));
                        if (!text.empty() && text.back() == '\r')
                            text.pop_back();
                        mAt = i + 1;
                        return text;
                    }
                }
                bad("the string at offset " + std::to_string(start) + " has no line feed before offset " +
                    std::to_string(end()));
            }

            /// Reads a chunk header inside the current chunk and opens it; returns its id.
            std::uint16_t openChunk()
            {
                const std::uint64_t at = mAt;
                need(6);
                const std::uint16_t id = u16();
                const std::uint32_t length = u32();
                const std::uint64_t parentEnd = end();
                mChunks.push_back({id, at, at + length});
                if (length < 6)
                    bad("length " + std::to_string(length) + " is shorter than the 6-byte chunk header");
                if (at + length > parentEnd)
                    bad("length " + std::to_string(length) + " runs to offset " + std::to_string(at + length) +
                        ", past the end of " + (mChunks.size() > 1 ? "its parent" : "the file") + " at " +
                        std::to_string(parentEnd));
                return id;
            }

            /// Ogre reads by chunk ids, not lengths: what it reads must end where the length says.
            void closeChunk()
            {
                if (mAt != end())
                    bad("what Ogre reads of it ends at offset " + std::to_string(mAt) + ", its length says " +
                        std::to_string(end()));
                mChunks.pop_back();
            }

            [[noreturn]] void notHeld(const std::string& parent, const std::string& kinds) const
            {
                bad("not a chunk " + parent + " holds (" + kinds + ")");
            }

            // ---- the format ----

            void header()
            {
                need(2);
                std::uint16_t id;
                std::memcpy(&id, mBytes.data(), 2);
                if (id == Ogre::M_HEADER)
                    mFlip = false;
                else if (id == std::uint16_t(Ogre::M_HEADER >> 8 | (Ogre::M_HEADER & 0xff) << 8))
                    mFlip = true;
                else
                    bad("the file starts with " + hex16(id) + ", not the .mesh header " + hex16(Ogre::M_HEADER));
                mAt = 2;
                const std::string version = string();
                if (version == "[MeshSerializer_v1.100]")
                    return;
                if (version == "[MeshSerializer_v1.8]")
                {
                    mV18 = true;
                    return;
                }
                for (const char* older : {"[MeshSerializer_v1.41]", "[MeshSerializer_v1.40]", "[MeshSerializer_v1.30]",
                                          "[MeshSerializer_v1.20]", "[MeshSerializer_v1.10]"})
                    if (version == older)
                        bad("format " + version + " is older than this importer reads ([MeshSerializer_v1.8] and "
                                                  "[MeshSerializer_v1.100]); upgrade the file with OgreMeshUpgrader");
                bad("unknown format version '" + version.substr(0, 40) + (version.size() > 40 ? "...'" : "'"));
            }

            void mesh()
            {
                boolean(); // skeletally animated
                while (mAt < end())
                {
                    switch (openChunk())
                    {
                    case Ogre::M_GEOMETRY:
                        if (mShared || !mSubs.empty())
                            bad(mShared ? "a second shared geometry" : "shared geometry after the submeshes");
                        mShared = true;
                        mSharedVertices = geometry();
                        break;
                    case Ogre::M_SUBMESH: submesh(); break;
                    case Ogre::M_MESH_SKELETON_LINK: string(); break;
                    case Ogre::M_MESH_BONE_ASSIGNMENT: boneAssignment(); break;
                    case Ogre::M_MESH_LOD_LEVEL: lodLevels(); break;
                    case Ogre::M_MESH_BOUNDS: bounds(); break;
                    case Ogre::M_SUBMESH_NAME_TABLE: nameTable(); break;
                    case Ogre::M_EDGE_LISTS: edgeLists(); break;
                    case Ogre::M_POSES: poses(); break;
                    case Ogre::M_ANIMATIONS: animations(); break;
                    case Ogre::M_TABLE_EXTREMES: extremes(); break;
                    default:
                        notHeld("M_MESH", "M_GEOMETRY, M_SUBMESH, M_MESH_SKELETON_LINK, M_MESH_BONE_ASSIGNMENT, "
                                          "M_MESH_LOD_LEVEL, M_MESH_BOUNDS, M_SUBMESH_NAME_TABLE, M_EDGE_LISTS, "
                                          "M_POSES, M_ANIMATIONS, M_TABLE_EXTREMES");
                    }
                    closeChunk();
                }
            }

            /// Ogre builds an AxisAlignedBox, which asserts (aborts, in Debian's build) unless
            /// min <= max on every axis.
            void bounds()
            {
                float box[6];
                for (float& v : box)
                    v = number<float>();
                for (int axis = 0; axis < 3; ++axis)
                    if (!(box[axis] <= box[axis + 3]))
                    {
                        std::ostringstream range;
                        range << "the bounds' " << "xyz"[axis] << " runs from " << box[axis] << " to " << box[axis + 3]
                              << " (the minimum must not exceed the maximum)";
                        bad(range.str());
                    }
                floats(1); // radius
            }

            void boneAssignment()
            {
                u32();     // vertex
                u16();     // bone
                floats(1); // weight
            }

            /// Inside an open M_GEOMETRY; returns its vertex count.
            std::uint32_t geometry()
            {
                struct Element
                {
                    std::uint16_t source, offset;
                    std::size_t size;
                };
                const std::uint32_t vertices = u32();
                std::vector<Element> elements;
                std::map<std::uint16_t, std::size_t> vertexSize; // per source, the sum of its elements
                std::set<std::uint16_t> buffers;
                bool declared = false;
                while (mAt < end())
                {
                    switch (openChunk())
                    {
                    case Ogre::M_GEOMETRY_VERTEX_DECLARATION:
                        if (declared || !buffers.empty())
                            bad(declared ? "a second vertex declaration" : "the vertex declaration after a buffer");
                        declared = true;
                        while (mAt < end())
                        {
                            if (openChunk() != Ogre::M_GEOMETRY_VERTEX_ELEMENT)
                                notHeld("M_GEOMETRY_VERTEX_DECLARATION", "M_GEOMETRY_VERTEX_ELEMENT");
                            const std::uint16_t source = u16(), type = u16(), semantic = u16(), offset = u16();
                            u16(); // index
                            if (type > Ogre::VET_USHORT4_NORM)
                                bad("vertex element type " + std::to_string(type) + " is not one Ogre 1.12 knows");
                            if (semantic < Ogre::VES_POSITION || semantic > Ogre::VES_TANGENT)
                                bad("vertex element semantic " + std::to_string(semantic) + " is not one Ogre knows");
                            const auto elementType = Ogre::VertexElementType(type);
                            const std::size_t size = Ogre::VertexElement::getTypeSize(elementType);
                            // MeshSerializerImpl::flipEndian asserts on these base types
                            const Ogre::VertexElementType base = Ogre::VertexElement::getBaseType(elementType);
                            if (mFlip && (base == Ogre::VET_SHORT2_NORM || base == Ogre::VET_USHORT2_NORM ||
                                          base == Ogre::VET_BYTE4 || base == Ogre::VET_BYTE4_NORM ||
                                          base == Ogre::VET_UBYTE4_NORM))
                                bad("vertex element type " + std::to_string(type) +
                                    " in a file of the other byte order: Ogre 1.12 cannot swap its bytes");
                            elements.push_back({source, offset, size});
                            vertexSize[source] += size;
                            closeChunk();
                        }
                        break;
                    case Ogre::M_GEOMETRY_VERTEX_BUFFER:
                    {
                        const std::uint16_t bind = u16(), size = u16();
                        const auto declaredSize = vertexSize.find(bind);
                        if (declaredSize == vertexSize.end())
                            bad("a buffer for source " + std::to_string(bind) + ", which no vertex element uses");
                        if (size != declaredSize->second)
                            bad("vertex size " + std::to_string(size) + " for source " + std::to_string(bind) +
                                ", its vertex elements take " + std::to_string(declaredSize->second) + " bytes");
                        if (!buffers.insert(bind).second)
                            bad("a second buffer for source " + std::to_string(bind));
                        if (openChunk() != Ogre::M_GEOMETRY_VERTEX_BUFFER_DATA)
                            bad("expected M_GEOMETRY_VERTEX_BUFFER_DATA, the buffer's data");
                        array(vertices, size, "vertices");
                        closeChunk();
                        break;
                    }
                    default:
                        notHeld("M_GEOMETRY", "M_GEOMETRY_VERTEX_DECLARATION, M_GEOMETRY_VERTEX_BUFFER");
                    }
                    closeChunk();
                }
                for (std::size_t i = 0; i < elements.size(); ++i)
                {
                    const Element& e = elements[i];
                    if (!buffers.count(e.source))
                        bad("vertex element " + std::to_string(i) + " reads source " + std::to_string(e.source) +
                            ", which has no buffer");
                    if (e.offset + e.size > vertexSize[e.source])
                        bad("vertex element " + std::to_string(i) + " (offset " + std::to_string(e.offset) + ", " +
                            std::to_string(e.size) + " bytes) lies outside the " +
                            std::to_string(vertexSize[e.source]) + "-byte vertices of source " +
                            std::to_string(e.source));
                }
                return vertices;
            }

            void submesh()
            {
                if (mSubs.size() == 0xffff)
                    bad("more than 65535 submeshes (Ogre counts them in 16 bits)");
                if (mLod || mEdges)
                    bad(std::string("a submesh after the ") + (mLod ? "LOD levels" : "edge lists") +
                        ", which cover the submeshes before them");
                string(); // material
                Sub sub;
                sub.shared = boolean();
                const std::uint32_t indices = u32();
                const bool index32 = boolean();
                if (indices > 0)
                    array(indices, index32 ? 4 : 2, "indices");
                if (!sub.shared)
                {
                    if (openChunk() != Ogre::M_GEOMETRY)
                        bad("expected the submesh's own M_GEOMETRY (it does not use the shared vertices)");
                    sub.vertices = geometry();
                    closeChunk();
                }
                else if (!mShared)
                    bad("uses shared vertices, and the mesh has none before it");
                mSubs.push_back(sub);
                while (mAt < end())
                {
                    switch (openChunk())
                    {
                    case Ogre::M_SUBMESH_OPERATION:
                    {
                        // Ogre stores it as an OperationType: only that enum's values
                        const std::uint16_t op = u16();
                        if (!(op >= Ogre::RenderOperation::OT_POINT_LIST &&
                              op <= Ogre::RenderOperation::OT_PATCH_32_CONTROL_POINT) &&
                            !(op >= Ogre::RenderOperation::OT_LINE_LIST_ADJ &&
                              op <= Ogre::RenderOperation::OT_TRIANGLE_STRIP_ADJ))
                            bad("operation type " + std::to_string(op) + " is not one Ogre knows");
                        break;
                    }
                    case Ogre::M_SUBMESH_BONE_ASSIGNMENT: boneAssignment(); break;
                    case Ogre::M_SUBMESH_TEXTURE_ALIAS:
                        string();
                        string();
                        break;
                    default:
                        notHeld("M_SUBMESH", "M_GEOMETRY first unless shared, M_SUBMESH_OPERATION, "
                                             "M_SUBMESH_BONE_ASSIGNMENT, M_SUBMESH_TEXTURE_ALIAS");
                    }
                    closeChunk();
                }
            }

            void lodLevels()
            {
                if (mLod || mEdges)
                    bad(mLod ? "a second M_MESH_LOD_LEVEL" : "LOD levels after the edge lists");
                mLod = true;
                string(); // strategy
                const std::uint16_t levels = u16();
                const bool manualV18 = mV18 && boolean();
                if (levels == 0)
                    bad("0 LOD levels (level 0 is the full mesh)");
                // Ogre sizes an index list per submesh and level before it reads a level, and
                // allocates an index set per submesh for each manual level: bound the product.
                const std::uint64_t slots = std::uint64_t(levels - 1) * mSubs.size();
                if (slots > mBytes.size())
                    bad(std::to_string(levels - 1) + " LOD levels x " + std::to_string(mSubs.size()) +
                        " submeshes: more index sets than the file has bytes (" + std::to_string(mBytes.size()) + ")");
                mLodCount = levels;
                mLodManual.assign(levels, false);
                // per level after 0 and submesh: the index count of its buffer, NO_BUFFER if none
                std::vector<std::vector<std::uint64_t>> lodBuffers(levels - 1,
                                                                   std::vector<std::uint64_t>(mSubs.size(), NO_BUFFER));
                for (std::uint16_t level = 1; level < levels; ++level)
                {
                    const std::uint16_t id = openChunk();
                    if (mV18)
                    {
                        if (id != Ogre::M_MESH_LOD_USAGE)
                            bad("expected M_MESH_LOD_USAGE for LOD level " + std::to_string(level));
                        floats(1); // usage value
                        if (manualV18)
                        {
                            if (openChunk() != Ogre::M_MESH_LOD_MANUAL)
                                bad("expected M_MESH_LOD_MANUAL (the levels are manual)");
                            mLodManual[level] = !string().empty(); // the level's mesh
                            closeChunk();
                        }
                        else
                            for (std::size_t s = 0; s < mSubs.size(); ++s)
                            {
                                if (openChunk() != Ogre::M_MESH_LOD_GENERATED)
                                    bad("expected M_MESH_LOD_GENERATED for submesh " + std::to_string(s));
                                const std::uint32_t indices = u32();
                                array(indices, boolean() ? 4 : 2, "indices");
                                closeChunk();
                            }
                    }
                    else if (id == Ogre::M_MESH_LOD_MANUAL)
                    {
                        floats(1);
                        mLodManual[level] = !string().empty();
                    }
                    else if (id == Ogre::M_MESH_LOD_GENERATED)
                    {
                        floats(1);
                        for (std::size_t s = 0; s < mSubs.size(); ++s)
                        {
                            const std::uint32_t count = u32(), start = u32(), bufferLevel = u32();
                            std::uint64_t& buffer = lodBuffers[level - 1][s];
                            if (bufferLevel == 0xffffffffu)
                            {
                                const bool index32 = boolean();
                                buffer = u32();
                                array(buffer, index32 ? 4 : 2, "indices");
                            }
                            else if (bufferLevel == 0 || bufferLevel >= level ||
                                     lodBuffers[bufferLevel - 1][s] == NO_BUFFER)
                                bad("submesh " + std::to_string(s) + " shares the index buffer of LOD level " +
                                    std::to_string(bufferLevel) + ", which has none before level " +
                                    std::to_string(level));
                            else
                                buffer = lodBuffers[bufferLevel - 1][s];
                            if (std::uint64_t(start) + count > buffer)
                                bad("submesh " + std::to_string(s) + " uses indices " + std::to_string(start) + " to " +
                                    std::to_string(std::uint64_t(start) + count) + " of a " + std::to_string(buffer) +
                                    "-index buffer");
                        }
                    }
                    else
                        bad("expected M_MESH_LOD_MANUAL or M_MESH_LOD_GENERATED for LOD level " +
                            std::to_string(level));
                    closeChunk();
                }
            }

            void nameTable()
            {
                while (mAt < end())
                {
                    if (openChunk() != Ogre::M_SUBMESH_NAME_TABLE_ELEMENT)
                        notHeld("M_SUBMESH_NAME_TABLE", "M_SUBMESH_NAME_TABLE_ELEMENT");
                    const std::uint16_t index = u16();
                    if (index >= mSubs.size())
                        bad("names submesh " + std::to_string(index) + " of " + std::to_string(mSubs.size()));
                    string();
                    closeChunk();
                }
            }

            void edgeLists()
            {
                mEdges = true;
                mEdgeLod.resize(mLodCount);
                while (mAt < end())
                {
                    if (openChunk() != Ogre::M_EDGE_LIST_LOD)
                        notHeld("M_EDGE_LISTS", "M_EDGE_LIST_LOD");
                    const std::uint16_t level = u16();
                    if (level >= mLodCount)
                        bad("LOD level " + std::to_string(level) + ", the mesh has " + std::to_string(mLodCount));
                    if (mEdgeLod[level])
                        bad("a second edge list for LOD level " + std::to_string(level));
                    mEdgeLod[level] = true;
                    if (!boolean()) // not manual: the edge data is here
                    {
                        // Mesh::freeEdgeList leaves a named manual level's edge data to its mesh
                        if (mLodManual[level])
                            bad("edge data for LOD level " + std::to_string(level) +
                                ", a manual level (its own mesh has its edges)");
                        boolean(); // closed
                        const std::uint32_t triangles = u32(), groups = u32();
                        array(triangles, 8 * 4 + 4 * 4, "triangles");
                        if (std::uint64_t(groups) * 22 > left()) // Ogre sizes the list first
                            bad(std::to_string(groups) + " edge groups need at least " +
                                std::to_string(std::uint64_t(groups) * 22) + " bytes, the chunk has " +
                                std::to_string(left()));
                        for (std::uint32_t g = 0; g < groups; ++g)
                        {
                            if (openChunk() != Ogre::M_EDGE_GROUP)
                                bad("expected M_EDGE_GROUP " + std::to_string(g) + " of " + std::to_string(groups));
                            const std::uint32_t vertexSet = u32(), start = u32(), count = u32(), edges = u32();
                            // vertex set 0 is the shared geometry when there is one, else submesh 0
                            if (std::uint64_t(vertexSet) >= mSubs.size() + (mShared ? 1 : 0))
                                bad("vertex set " + std::to_string(vertexSet) + " names no geometry");
                            if (std::uint64_t(start) + count > triangles)
                                bad("triangles " + std::to_string(start) + " to " +
                                    std::to_string(std::uint64_t(start) + count) + " of " + std::to_string(triangles));
                            array(edges, 6 * 4 + 1, "edges");
                            closeChunk();
                        }
                    }
                    closeChunk();
                }
            }

            /// A pose's or vertex track's target: 0 the shared geometry, n submesh n - 1's own.
            /// Returns its vertex count.
            std::uint32_t target(std::uint16_t handle)
            {
                if (handle == 0 && !mShared)
                    bad("target 0 (the shared geometry), which the mesh does not have");
                if (handle > 0 && (handle > mSubs.size() || mSubs[handle - 1].shared))
                    bad("target " + std::to_string(handle) + " (submesh " + std::to_string(handle - 1) +
                        "), which has no geometry of its own");
                return handle == 0 ? mSharedVertices : mSubs[handle - 1].vertices;
            }

            void poses()
            {
                while (mAt < end())
                {
                    if (openChunk() != Ogre::M_POSE)
                        notHeld("M_POSES", "M_POSE");
                    string(); // name
                    target(u16());
                    const bool normals = boolean();
                    ++mPoses;
                    while (mAt < end())
                    {
                        if (openChunk() != Ogre::M_POSE_VERTEX)
                            notHeld("M_POSE", "M_POSE_VERTEX");
                        u32();
                        floats(normals ? 6 : 3);
                        closeChunk();
                    }
                    closeChunk();
                }
            }

            void animations()
            {
                while (mAt < end())
                {
                    if (openChunk() != Ogre::M_ANIMATION)
                        notHeld("M_ANIMATIONS", "M_ANIMATION");
                    const std::string name = string();
                    if (!mAnimations.insert(name).second)
                        bad("a second animation named '" + name + "'");
                    floats(1); // length
                    // Ogre reads a base-info chunk next as this animation's, and its writer leaves
                    // that chunk out of the animation's length and the enclosing ones.
                    if (mAt + 6 <= mBytes.size() && peek<std::uint16_t>(mAt) == Ogre::M_ANIMATION_BASEINFO)
                        widen(peek<std::uint32_t>(mAt + 2), "the animation's length leaves out its base info "
                                                             "(as Ogre's writer does)");
                    std::set<std::uint16_t> targets;
                    for (bool first = true; mAt < end(); first = false)
                    {
                        const std::uint16_t id = openChunk();
                        if (id == Ogre::M_ANIMATION_BASEINFO && first)
                        {
                            string();
                            floats(1);
                        }
                        else if (id == Ogre::M_ANIMATION_TRACK)
                            track(targets);
                        else
                            notHeld("M_ANIMATION", "M_ANIMATION_BASEINFO first, M_ANIMATION_TRACK");
                        closeChunk();
                    }
                    closeChunk();
                }
            }

            void track(std::set<std::uint16_t>& targets)
            {
                const std::uint16_t type = u16(), handle = u16();
                if (type != Ogre::VAT_MORPH && type != Ogre::VAT_POSE)
                    bad("vertex animation type " + std::to_string(type) + " (1 morph, 2 pose)");
                const std::uint32_t vertices = target(handle);
                if (!targets.insert(handle).second)
                    bad("a second track for target " + std::to_string(handle));
                while (mAt < end())
                {
                    const std::uint16_t id = openChunk();
                    if (id == Ogre::M_ANIMATION_MORPH_KEYFRAME && type == Ogre::VAT_MORPH)
                    {
                        floats(1); // time
                        const std::uint64_t data = std::uint64_t(vertices) * (boolean() ? 24 : 12);
                        // Ogre up to 1.13 left the bool out of this chunk's length, and so out of
                        // every enclosing chunk's: such a file ends one byte later per keyframe.
                        if (left() + 1 == data)
                            widen(1, "the keyframe's length leaves out its normals flag (as Ogre 1.12 writes it)");
                        array(data / 4, 4, "floats");
                    }
                    else if (id == Ogre::M_ANIMATION_POSE_KEYFRAME && type == Ogre::VAT_POSE)
                    {
                        floats(1);
                        while (mAt < end())
                        {
                            if (openChunk() != Ogre::M_ANIMATION_POSE_REF)
                                notHeld("M_ANIMATION_POSE_KEYFRAME", "M_ANIMATION_POSE_REF");
                            const std::uint16_t pose = u16();
                            if (pose >= mPoses)
                                bad("pose " + std::to_string(pose) + " of " + std::to_string(mPoses));
                            floats(1);
                            closeChunk();
                        }
                    }
                    else
                        notHeld(type == Ogre::VAT_MORPH ? "a morph M_ANIMATION_TRACK" : "a pose M_ANIMATION_TRACK",
                                type == Ogre::VAT_MORPH ? "M_ANIMATION_MORPH_KEYFRAME" : "M_ANIMATION_POSE_KEYFRAME");
                    closeChunk();
                }
            }

            void extremes()
            {
                const std::uint16_t sub = u16();
                if (sub >= mSubs.size())
                    bad("extremes of submesh " + std::to_string(sub) + " of " + std::to_string(mSubs.size()));
                // Ogre takes the point count from the chunk length
                if (left() % 12 != 0)
                    bad(std::to_string(left()) + " bytes of points, not a whole number of 12-byte points");
                mAt = end();
            }
        };
    }

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
            // MeshFileCheck guarantees both for a file; a mesh built in code may break them.
            if (e->getOffset() + e->getSize() > buffer->getVertexSize() ||
                data.vertexStart + data.vertexCount > buffer->getNumVertices())
            {
                error = "vertex element " + std::to_string(int(semantic)) + " lies outside its vertex buffer";
                return false;
            }
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
                if (indexData.indexStart + indexData.indexCount > ib->getNumIndexes())
                    return fail(file, element, "indices " + std::to_string(indexData.indexStart) + " to " +
                                                   std::to_string(indexData.indexStart + indexData.indexCount) +
                                                   " of a " + std::to_string(ib->getNumIndexes()) + "-index buffer");
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
        /// The tree in an imported mesh; `fileMaterialNames` per submesh as the file has them.
        Result<TreeModel> meshToModel(const Ogre::Mesh& mesh, const std::vector<std::string>& fileMaterialNames,
                                      const std::string& path, const OgreMeshImportOptions& options)
        {
            TreeModel model;
            model.name = std::filesystem::path(path).stem().string();
            std::map<std::string, std::uint32_t> materialIndex;
            detail::LeafSoup soup;
            for (unsigned short s = 0; s < mesh.getNumSubMeshes(); ++s)
            {
                Ogre::SubMesh* sub = mesh.getSubMesh(s);
                const std::string matName =
                    s < fileMaterialNames.size() ? fileMaterialNames[s] : sub->getMaterialName();
                const std::string element = "submesh " + std::to_string(s) + " '" + matName + "'";
                const Ogre::VertexData* vd = sub->useSharedVertices ? mesh.sharedVertexData : sub->vertexData;
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
                    if (loadMaterialTexture(matName, mesh.getGroup(), texture))
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
                    if (!std::isfinite(out.position.x) || !std::isfinite(out.position.y) ||
                        !std::isfinite(out.position.z))
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

        /// Records submesh material names as the file has them: SubMesh keeps only the
        /// names of materials Ogre knows, and a tree's scripts are often not loaded. Drops the
        /// skeleton name: the import takes no skeleton, so the file names none for Ogre to load.
        struct MaterialNameRecorder : Ogre::MeshSerializerListener
        {
            std::vector<std::string> names;
            void processMaterialName(Ogre::Mesh*, Ogre::String* name) override { names.push_back(*name); }
            void processSkeletonName(Ogre::Mesh*, Ogre::String* name) override { name->clear(); }
            void processMeshCompleted(Ogre::Mesh*) override {}
        };
    }

    Result<TreeModel> importOgreMesh(const std::string& path, const OgreMeshImportOptions& options)
    {
        Result<std::vector<std::uint8_t>> bytes = readFile(path);
        if (!bytes)
            return bytes.error();
        try
        {
            MeshFileCheck(bytes.value()).run();
        }
        catch (const MeshFileError& e)
        {
            return fail(path, e.element, e.reason);
        }
        static std::uint64_t counter = 0;
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

        // Reading the buffers back can throw too (a buffer Ogre cannot lock).
        try
        {
            return meshToModel(*mesh, recorder.names, path, options);
        }
        catch (const Ogre::Exception& e)
        {
            return fail(path, "mesh", e.getDescription());
        }
    }
}
