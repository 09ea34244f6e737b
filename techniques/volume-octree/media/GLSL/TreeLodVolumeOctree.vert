#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#elif defined(OGRE_GLSL)
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
#include "TreeLodTransition.glsl"
// The volumetric octree tree (VolumeOctreeData.h; Linz et al. 2006): one billboard a cell, facing
// the viewer (the camera's right and up axes in the model's frame), its corners (+-1, +-1).
// - Level of detail (§3.1, volumeOctreeDrawsCell): a cell of the active level L draws when its
//   parent's centre lies in front of L's distance plane, a cell of level L - 1 when its own centre
//   lies behind it; any other cell collapses off screen.
// - Texture (§2.1): the two input cameras nearest the view; each one's slot gives a colour and an
//   alpha codeword (§4.1), a 4x4 block of the atlas; a pruned slot (§3.2) gives weight 0.
// Single tree (VolumeOctreeTree): the vertices are the cells in the object's back-to-front order;
// the camera pair, active level and plane come per object from the CPU. With a transition band
// (TreeLod/ObjectTransition.h) a cell of the level above in front of the plane, within the band's
// end of it in screen size (plane depth over its centre's), draws too, and it and its children
// keep complementary screen-door shares (TreeLodTransition.glsl).
// INSTANCED (a Forest level, VolumeOctreeForestGpu): the corners of quad q fetch the cell of entry
// q of its tree's view octant in the level's orders, so each tree of one draw has its own order;
// the camera pair (volumeOctreeCameraPair) is chosen here from each tree's view of the camera,
// and L's plane lies at cellEdge(L) * scale * focal * sqrt(LoD bias) / lodPixels.
// CASTER: the same billboards facing the shadow camera, the two input cameras nearest the light,
//   the active level everywhere; passes clip z and w and the cell on.
uniform mat4 worldViewProj;
uniform mat4 worldView;
uniform mat4 world;        // the wind (TreeLodWind.glsl): each cell moves rigidly with the mesh's
uniform mat4 inverseWorld; // points at its centre; levels are chosen at rest
uniform vec4 octree;     // cameras, slot texture width, atlas blocks a row, atlas width
SAMPLER2D(slots, 1);
#ifdef INSTANCED
#include "TreeLodInstance.glsl"
uniform mat4 projection;
uniform vec4 viewportSize;
uniform vec4 eyePosition;     // the camera in the Forest's local space
uniform vec4 lengthFactor;    // custom 0: x = sqrt(LoD bias) / lodPixels
uniform vec4 forestLevel;     // custom 1: L, first order entry, quads n(L), cellEdge(L)
uniform vec4 octreeBox;       // origin, root edge (model metres)
uniform vec4 cameraDirections[64]; // VOLUME_OCTREE_MAX_CAMERAS
uniform float texelsWidth;
SAMPLER2D(cells, 2);          // RGBA8: x | y << 9 | z << 18 | level << 27
SAMPLER2D(orders, 3);         // RGBA8: cell indices
#else
uniform vec4 lodState;   // active level, plane depth (view metres), weight of camera 0, of camera 1
uniform vec4 cameraPair; // input camera 0, input camera 1, transition band's end (1: none), pattern shift
#endif
#include "TreeLodWind.glsl"

// The codewords of the slot of `cell` for `camera`: (colour, alpha), -1 when pruned.
ivec2 codewords(int cell, int camera)
{
    int slot = cell * int(octree.x) + camera;
    int width = int(octree.y);
    vec4 bytes = TEX2D_FETCH(slots, ivec2(slot % width, slot / width), 0) * 255.0 + 0.5;
    int colour = int(bytes.r) + 256 * int(bytes.g);
    int alpha = int(bytes.b) + 256 * int(bytes.a);
    return colour == 65535 ? ivec2_splat(-1) : ivec2(colour, alpha);
}

vec2 blockOrigin(int block)
{
    int perRow = int(octree.z);
    return 4.0 * vec2(float(block % perRow), float(block / perRow));
}

#ifdef INSTANCED
// Entry i of a texture of 32-bit words (VolumeOctreeForestGpu).
int fetchWord(SAMPLER2D_PARAM(map), int i)
{
    int width = int(texelsWidth);
    ivec4 b = ivec4(TEX2D_FETCH(map, ivec2(i % width, i / width), 0) * 255.0 + 0.5);
    return b.r | (b.g << 8) | (b.b << 16) | (b.a << 24);
}

// volumeOctreeCameraPair: the two cameras nearest `towards` (ties: lower index first), weighted
// by the angle to the other one. Returns (first, second, first's weight).
vec3 cameraPairOf(vec3 towards)
{
    int count = int(octree.x);
    float best = -2.0, second = -2.0;
    int first = 0, next = 0;
    for (int i = 0; i < count; ++i)
    {
        float d = dot(cameraDirections[i].xyz, towards);
        if (d > best)
        {
            second = best;
            next = first;
            best = d;
            first = i;
        }
        else if (d > second)
        {
            second = d;
            next = i;
        }
    }
    if (count < 2)
        return vec3(float(first), float(first), 1.0);
    float a0 = acos(clamp(best, -1.0, 1.0)), a1 = acos(clamp(second, -1.0, 1.0));
    return vec3(float(first), float(next), a0 + a1 > 0.0 ? a1 / (a0 + a1) : 1.0);
}
#endif

MAIN_PARAMETERS
#ifdef INSTANCED
    IN(float vertex, POSITION) // 4 quad + corner (0 to 3 counter-clockwise from (-1, -1))
    INSTANCE_IN
#else
    IN(vec4 vertex, POSITION)  // the cell's centre
    IN(vec4 uv0, TEXCOORD0)    // corner x, corner y, level, cell index
    IN(vec4 uv1, TEXCOORD1)    // the parent's centre, half the cell's edge
#endif
    OUT(vec2 vTexel, TEXCOORD0)             // billboard texels, (0, 0) top-left, (4, 4) bottom-right
    FLAT_OUT(vec4 vColourBlocks, TEXCOORD1) // atlas texel origins of camera 0's and camera 1's colour codewords
    FLAT_OUT(vec4 vAlphaBlocks, TEXCOORD2)  // ... of their alpha codewords
    FLAT_OUT(vec2 vWeights, TEXCOORD3)
#ifdef CASTER
    OUT(vec2 vClipZW, TEXCOORD4)
    FLAT_OUT(float vCell, TEXCOORD5)
#endif
    TRANSITION_OUT(TEXCOORD6)
MAIN_DECLARATION
{
#ifdef INSTANCED
    vTransition = transitionOf(uv4, uv5);
#endif
#ifdef INSTANCED
    int quad = int(vertex + 0.5) / 4, c = int(vertex + 0.5) % 4;
    vec2 corner = vec2(c == 1 || c == 2 ? 1.0 : -1.0, c >= 2 ? 1.0 : -1.0);
    // The camera in the tree's frame (orthographic: from its direction).
    vec3 rootCentre = octreeBox.xyz + 0.5 * octreeBox.w;
    bool orthographic = projection[3][3] > 0.5;
    vec3 towards = orthographic
                       ? instanceLocalDirection(uv5, normalize(row3(worldView, 2)))
                       : normalize(instanceLocalDirection(uv5, eyePosition.xyz - uv4.xyz) / uv4.w - rootCentre);
    int octant = (towards.x > 0.0 ? 1 : 0) + (towards.y > 0.0 ? 2 : 0) + (towards.z > 0.0 ? 4 : 0);
    int cell = fetchWord(SAMPLER2D_ARG(orders), int(forestLevel.y) + octant * int(forestLevel.z) + quad);
    int word = fetchWord(SAMPLER2D_ARG(cells), cell);
    ivec3 coords = ivec3(word & 511, (word >> 9) & 511, (word >> 18) & 511);
    float level = float((word >> 27) & 15);
    float activeLevel = forestLevel.x;
    float edge = octreeBox.w / exp2(level);
    float halfEdge = 0.5 * edge;
    vec3 parentCentre = octreeBox.xyz + (vec3(coords / 2) + 0.5) * (2.0 * edge);
    vec3 cellCentre = octreeBox.xyz + (vec3(coords) + 0.5) * edge;
    vec4 centre = instancePosition(uv4, uv5, vec4(cellCentre, 1.0));
    float depth = -mul(worldView, centre).z;
    float parentDepth = -mul(worldView, instancePosition(uv4, uv5, vec4(parentCentre, 1.0))).z;
#ifdef CASTER
    float plane = 3.0e38;
#else
    float focal = abs(projection[1][1]) * 0.5 * viewportSize.y; // render targets may flip y
    float plane = orthographic ? 3.0e38 : forestLevel.w * uv4.w * focal * lengthFactor.x;
#endif
    vec3 pair = cameraPairOf(towards);
    vec4 lodState = vec4(activeLevel, plane, pair.z, 1.0 - pair.z);
    vec2 cameraPair = pair.xy;
    float size = halfEdge * uv4.w;
    float cellIndex = float(cell);
#else
    float level = uv0.z;
    float activeLevel = lodState.x;
    vec4 centre = vec4(vertex.xyz, 1.0);
    float depth = -mul(worldView, centre).z;
    float parentDepth = -mul(worldView, vec4(uv1.xyz, 1.0)).z;
    float size = uv1.w;
    float cellIndex = uv0.w;
    vec2 corner = uv0.xy;
#endif
    bool drawn = activeLevel < 0.5 ? level < 0.5
                              : (abs(level - activeLevel) < 0.5 ? parentDepth < lodState.y
                                                           : abs(level + 1.0 - activeLevel) < 0.5 && depth >= lodState.y);
#ifndef INSTANCED
    // The band: both a cell of the level above and its children draw while the cell's centre is
    // within cameraPair.z of the plane (in screen size), each keeping its share.
    float share = 0.0;
    if (activeLevel >= 0.5 && abs(level - activeLevel) < 0.5 && drawn)
        share = -transitionCoarseShare(lodState.y / max(parentDepth, 1e-6), cameraPair.z);
    else if (activeLevel >= 0.5 && abs(level + 1.0 - activeLevel) < 0.5 && depth < lodState.y)
    {
        share = transitionCoarseShare(lodState.y / max(depth, 1e-6), cameraPair.z);
        drawn = share > 0.0;
    }
    vTransition = vec2(share, cameraPair.w);
#endif
    ivec2 first = codewords(int(cellIndex + 0.5), int(cameraPair.x + 0.5));
    ivec2 second = codewords(int(cellIndex + 0.5), int(cameraPair.y + 0.5));
    vWeights = vec2(first.x >= 0 ? lodState.z : 0.0, second.x >= 0 ? lodState.w : 0.0);
    if (!drawn || vWeights.x + vWeights.y <= 0.0)
    {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0); // outside the clip volume
        vTexel = vec2_splat(0.0);
        vColourBlocks = vec4_splat(0.0);
        vAlphaBlocks = vec4_splat(0.0);
#ifdef CASTER
        vClipZW = vec2(0.0, 1.0);
        vCell = 0.0;
#endif
        return;
    }
    vColourBlocks = vec4(blockOrigin(max(first.x, 0)), blockOrigin(max(second.x, 0)));
    vAlphaBlocks = vec4(blockOrigin(max(first.y, 0)), blockOrigin(max(second.y, 0)));
#ifdef INSTANCED
    centre.xyz += uv4.w * instanceDirection(uv5, windInstanceOffset(cellCentre, uv4, uv5, world, inverseWorld, false));
#else
    centre.xyz += windObjectOffset(vertex.xyz, world, inverseWorld, false);
#endif
    vec3 right = normalize(row3(worldView, 0));
    vec3 up = normalize(row3(worldView, 1));
    vec3 position = centre.xyz + (corner.x * right + corner.y * up) * size;
    vTexel = vec2(corner.x + 1.0, 1.0 - corner.y) * 2.0;
    gl_Position = mul(worldViewProj, vec4(position, 1.0));
#ifdef CASTER
    vClipZW = gl_Position.zw;
    vCell = cellIndex;
#endif
}
