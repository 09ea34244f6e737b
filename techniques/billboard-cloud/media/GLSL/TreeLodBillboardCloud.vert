#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#elif defined(OGRE_GLSL)
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
#include "TreeLodTransition.glsl"
// Billboard cloud quads (García et al. 2007 §4.2, §6; vertex layout in TreeLod/TreeAsset.h,
// BillboardCloudGpu): the billboard frame in world space, its (u, v), hash rectangle and
// low-res rectangle to the fragment stage.
// CASTER: the shadow camera's clip z and w, and the direction towards the light (the shadow
// camera's view +z, a directional light) instead of the camera.
// SHADOW_RECEIVER: the position in the sun's shadow texture.
// INSTANCED: placed by the Forest's instance data first (TreeLodInstance.glsl).
// Each corner moves with the wind as the mesh's points there do (TreeLodWind.glsl).
uniform mat4 worldViewProj;
uniform mat4 world;
uniform mat4 inverseWorld;
#ifdef CASTER
uniform mat4 view;
#else
uniform mat4 normalMatrix;
uniform vec4 cameraPosition;
#endif
uniform vec4 objectTransition; // custom 7 (TreeLod/ObjectTransition.h)
#ifdef SHADOW_RECEIVER
#include "TreeLodShadowReceiver.glsl"
#endif
#ifdef INSTANCED
#include "TreeLodInstance.glsl"
#endif
#include "TreeLodWind.glsl"

MAIN_PARAMETERS
    IN(vec4 vertex, POSITION)
    IN(vec3 normal, NORMAL)
    IN(vec3 tangent, TANGENT)
    IN(vec2 uv0, TEXCOORD0)
    IN(vec4 uv1, TEXCOORD1)
    IN(vec4 uv2, TEXCOORD2)
#ifdef INSTANCED
    INSTANCE_IN
#endif
    OUT(vec2 vUv, TEXCOORD0)
    OUT(vec2 vLowResUv, TEXCOORD1)
    FLAT_OUT(vec4 vHash, TEXCOORD2)
    OUT(vec3 vNormal, TEXCOORD3)
    OUT(vec3 vTangent, TEXCOORD4)
    OUT(vec3 vToCamera, TEXCOORD5)
#ifdef CASTER
    OUT(vec2 vClipZW, TEXCOORD6)
#endif
#ifdef SHADOW_RECEIVER
    SHADOW_POSITIONS_OUT(TEXCOORD7, TEXCOORD8, TEXCOORD9)
#endif
    TRANSITION_OUT(TEXCOORD10)
MAIN_DECLARATION
{
#ifdef INSTANCED
    vTransition = drawTransition(uv4, uv5, objectTransition);
#else
    vTransition = objectTransition.xy;
#endif
#ifdef INSTANCED
    vec4 rest = vec4(vertex.xyz + windInstanceOffset(vertex.xyz, uv4, uv5, world, inverseWorld, false), 1.0);
    vec4 local = instancePosition(uv4, uv5, rest);
    vec3 objectNormal = instanceDirection(uv5, normal);
    vec3 objectTangent = instanceDirection(uv5, tangent);
#else
    vec4 local = vec4(vertex.xyz + windObjectOffset(vertex.xyz, world, inverseWorld, false), 1.0);
    vec3 objectNormal = normal;
    vec3 objectTangent = tangent;
#endif
    gl_Position = mul(worldViewProj, local);
    vec3 position = mul(world, local).xyz;
#ifdef CASTER
    vClipZW = gl_Position.zw;
    vNormal = mul(toMat3(world), objectNormal);
    vToCamera = row3(view, 2);
#else
    vNormal = mul(toMat3(normalMatrix), objectNormal);
    vToCamera = cameraPosition.xyz - position;
#endif
    vTangent = mul(toMat3(world), objectTangent);
    vUv = uv0;
    vHash = uv1;
    vLowResUv = mix(uv2.xy, uv2.zw, uv0);
#ifdef SHADOW_RECEIVER
    passShadowPositions(vec4(position, 1.0));
#endif
}
