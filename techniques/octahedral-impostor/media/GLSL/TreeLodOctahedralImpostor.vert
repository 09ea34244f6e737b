#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#elif defined(OGRE_GLSL)
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
#include "TreeLodTransition.glsl"
// The octahedral impostor (OctahedralImpostorData.h), instanced by the Forest (Forest.h,
// TreeLodInstance.glsl). Per instance, from the direction v towards the camera (CASTER: towards
// the light) turned into the tree's own frame:
// - the quad: corners (+-1, +-1) (vertex.xy) spread over the bounding cylinder's projection seen
//   from v (octahedralHalfHeight), facing v, grown by the frames' margins;
// - the three frames of the hemi-octahedral grid around v and their barycentric weights
//   (Brucks 2018: the triangle of the grid cell v falls in);
// - per frame: the frame coordinates of this corner projected along v onto the frame's plane
//   (exact for a planar quad: the map is affine), the shift of those coordinates per unit of
//   stored depth (the fragment stage's one-step parallax: a surface d in front of the plane is
//   seen d / (v . t) further along v), and the sun in the frame's axes (lighting without turning
//   anything per fragment, as TreeLodImpostor.vert).
// The frame mapping mirrors OctahedralImpostorData.cpp (hemiOctahedralEncode/Decode,
// octahedralFrameAxes, octahedralHalfHeight, octahedralFrameSide).
// SHADOW_RECEIVER: the position in the sun's shadow texture. CASTER: clip z and w.
// Wind (TreeLodWind.glsl): each corner moves with the mesh's points there.
uniform mat4 worldViewProj;
uniform mat4 world;
uniform mat4 inverseWorld;
uniform vec4 cylinder; // radius, bottom, top, depth radius (metres, the tree's own frame)
uniform vec4 atlas;    // frames a side N, frame texels F, margin texels, 0
#ifdef CASTER
uniform mat4 view;
#else
uniform vec4 cameraPosition; // in the Forest's local space
uniform vec4 sunDirection;   // world space, towards the sun
#endif
#ifdef SHADOW_RECEIVER
#include "TreeLodShadowReceiver.glsl"
#endif
#include "TreeLodInstance.glsl"
#include "TreeLodWind.glsl"

vec2 hemiOctahedralEncode(vec3 d)
{
    d.y = max(d.y, 0.0);
    float l1 = abs(d.x) + d.y + abs(d.z);
    if (l1 <= 0.0)
        return vec2_splat(0.0);
    vec2 xz = d.xz / l1;
    return vec2(xz.x + xz.y, xz.x - xz.y);
}

vec3 hemiOctahedralDecode(vec2 p)
{
    float x = 0.5 * (p.x + p.y), z = 0.5 * (p.x - p.y);
    return normalize(vec3(x, max(1.0 - abs(x) - abs(z), 0.0), z));
}

void frameAxes(vec3 towards, out vec3 right, out vec3 up)
{
    vec3 r = cross(vec3(0.0, 1.0, 0.0), towards);
    float l = length(r);
    right = l > 1e-6 ? r / l : vec3(1.0, 0.0, 0.0);
    up = cross(towards, right);
}

float halfHeight(vec3 up) { return 0.5 * (cylinder.z - cylinder.y) * abs(up.y) + cylinder.x * length(up.xz); }

float marginScale() { return atlas.y / (atlas.y - 2.0 * atlas.z); }


/// Frame `cell`: this corner's frame coordinates (xy) and their shift per unit of encoded depth
/// (zw); the sun in the frame's axes.
vec4 frameCoordinates(vec2 cell, vec3 v, vec3 corner, vec3 sunInTree, out vec3 sunInFrame)
{
    vec3 t = hemiOctahedralDecode(cell / (atlas.x - 1.0) * 2.0 - 1.0);
    vec3 right, up;
    frameAxes(t, right, up);
    float side = max(2.0 * cylinder.x, 2.0 * halfHeight(up)) * marginScale();
    float vt = max(dot(v, t), 0.05);
    vec3 onPlane = corner - v * (dot(corner, t) / vt);
    vec2 uv = vec2(0.5 + dot(onPlane, right) / side, 0.5 - dot(onPlane, up) / side);
    // Encoded depth e is d = (e - 0.5) * 2 * depth radius metres in front of the plane.
    vec2 shift = (2.0 * cylinder.w / (vt * side)) * vec2(dot(v, right), -dot(v, up));
    sunInFrame = vec3(dot(sunInTree, right), dot(sunInTree, up), dot(sunInTree, t));
    return vec4(uv, shift);
}

MAIN_PARAMETERS
    IN(vec4 vertex, POSITION)
    INSTANCE_IN
    OUT(vec4 vUv01, TEXCOORD0) // frame coordinates (0..1 within a frame) of frames 0 and 1
    OUT(vec2 vUv2, TEXCOORD1)
    FLAT_OUT(vec4 vFrame01, TEXCOORD2) // frame column, row of frames 0 and 1
    FLAT_OUT(vec2 vFrame2, TEXCOORD3)
    FLAT_OUT(vec3 vWeights, TEXCOORD4)
#ifdef CASTER
    OUT(vec2 vClipZW, TEXCOORD5)
#else
    OUT(vec3 vSun0, TEXCOORD5)
    OUT(vec3 vSun1, TEXCOORD6)
    OUT(vec3 vSun2, TEXCOORD7)
    OUT(vec4 vParallax01, TEXCOORD8) // frames 0 and 1: frame-coordinate shift per unit of (depth - 0.5)
    OUT(vec2 vParallax2, TEXCOORD9)
#endif
#ifdef SHADOW_RECEIVER
    SHADOW_POSITIONS_OUT(TEXCOORD10, TEXCOORD11, TEXCOORD12)
#endif
    TRANSITION_OUT(TEXCOORD13)
MAIN_DECLARATION
{
    vTransition = transitionOf(uv4, uv5);
    float centreY = 0.5 * (cylinder.y + cylinder.z);
    vec3 centre = uv4.xyz + vec3(0.0, uv4.w * centreY, 0.0);
#ifdef CASTER
    vec3 away = mul(transpose(toMat3(world)), row3(view, 2));
#else
    vec3 away = cameraPosition.xyz - centre;
#endif
    vec3 v = dot(away, away) > 0.0 ? instanceLocalDirection(uv5, normalize(away)) : vec3(0.0, 0.0, 1.0);

    // The quad, facing v.
    vec3 right, up;
    frameAxes(v, right, up);
    vec3 corner = (vertex.x * cylinder.x * right + vertex.y * halfHeight(up) * up) * marginScale();
    corner += windInstanceOffset(corner + vec3(0.0, centreY, 0.0), uv4, uv5, world, inverseWorld, false);
    vec4 position = vec4(centre + uv4.w * instanceDirection(uv5, corner), 1.0);
    gl_Position = mul(worldViewProj, position);

    // The three frames around v.
    vec2 grid = (hemiOctahedralEncode(v) * 0.5 + 0.5) * (atlas.x - 1.0);
    vec2 base = clamp(floor(grid), vec2_splat(0.0), vec2_splat(atlas.x - 2.0));
    vec2 f = clamp(grid - base, 0.0, 1.0);
    vec2 cell0, cell1 = base + vec2(1.0, 0.0), cell2 = base + vec2(0.0, 1.0);
    if (f.x + f.y <= 1.0)
    {
        cell0 = base;
        vWeights = vec3(1.0 - f.x - f.y, f.x, f.y);
    }
    else
    {
        cell0 = base + vec2_splat(1.0);
        vWeights = vec3(f.x + f.y - 1.0, 1.0 - f.y, 1.0 - f.x);
    }
    vFrame01 = vec4(cell0, cell1);
    vFrame2 = cell2;

#ifdef CASTER
    vec3 sunInTree = vec3_splat(0.0);
#else
    vec3 sunInTree = instanceLocalDirection(uv5, normalize(mul(transpose(toMat3(world)), normalize(sunDirection.xyz))));
#endif
    vec3 sun0, sun1, sun2;
    vec4 c0 = frameCoordinates(cell0, v, corner, sunInTree, sun0);
    vec4 c1 = frameCoordinates(cell1, v, corner, sunInTree, sun1);
    vec4 c2 = frameCoordinates(cell2, v, corner, sunInTree, sun2);
    vUv01 = vec4(c0.xy, c1.xy);
    vUv2 = c2.xy;
#ifdef CASTER
    vClipZW = gl_Position.zw;
#else
    vParallax01 = vec4(c0.zw, c1.zw);
    vParallax2 = c2.zw;
    vSun0 = sun0;
    vSun1 = sun1;
    vSun2 = sun2;
#endif
#ifdef SHADOW_RECEIVER
    passShadowPositions(mul(world, position));
#endif
}
