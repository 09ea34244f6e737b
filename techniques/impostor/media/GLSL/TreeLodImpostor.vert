#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#elif defined(OGRE_GLSL)
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
#include "TreeLodTransition.glsl"
// The one-quad impostor (ImpostorData.h), instanced by the Forest (Forest.h): per instance
// uv4 = position (the Forest's local space) + uniform scale, uv5 = cos, sin of the rotation
// about +Y (unused) and the transition code (TreeLodTransition.glsl): the quad (vertex.xy,
// metres, facing +Z) turns about the instance's +Y axis until its +Z faces the camera (a
// cylindrical billboard), so the tree's rotation cannot show.
// The sun's direction goes to the fragment stage in the quad frame (x right, y up, z towards
// the camera), the frame of the baked normals: one value per quad, so the fragment stage lights
// without turning or normalising anything.
// CASTER: faces the light: the shadow camera's view +z (a directional light's direction) instead
// of the camera position; passes clip z and w on.
// SHADOW_RECEIVER: the position in the sun's shadow texture.
// Wind (TreeLodWind.glsl): each corner moves with the mesh's points there, so the quad sways and
// shears with the trunk.
uniform mat4 worldViewProj;
uniform mat4 world;
uniform mat4 inverseWorld;
#ifdef CASTER
uniform mat4 view;
#else
uniform vec4 cameraPosition; // in the Forest's local space
uniform vec4 sunDirection;   // world space, towards the sun (w = 0 for a directional light)
#endif
#ifdef SHADOW_RECEIVER
#include "TreeLodShadowReceiver.glsl"
#endif
#include "TreeLodInstance.glsl"
#include "TreeLodWind.glsl"

MAIN_PARAMETERS
    IN(vec4 vertex, POSITION)
    IN(vec2 uv0, TEXCOORD0)
    INSTANCE_IN
    OUT(vec2 vUv, TEXCOORD0)
#ifdef CASTER
    OUT(vec2 vClipZW, TEXCOORD1)
#else
    OUT(vec3 vSunInQuad, TEXCOORD1)
#endif
#ifdef SHADOW_RECEIVER
    SHADOW_POSITIONS_OUT(TEXCOORD2, TEXCOORD3, TEXCOORD4)
#endif
    TRANSITION_OUT(TEXCOORD5)
MAIN_DECLARATION
{
    vTransition = transitionOf(uv4, uv5);
    vec3 centre = uv4.xyz;
#ifdef CASTER
    // The view's +z axis (towards the shadow camera) in the Forest's local space.
    vec3 away = mul(transpose(toMat3(world)), row3(view, 2));
#else
    vec3 away = cameraPosition.xyz - centre;
#endif
    // Straight above or below: keep the quad's own orientation.
    vec2 f = dot(away.xz, away.xz) > 1e-12 * dot(away, away) ? normalize(away.xz) : vec2(0.0, 1.0);
    vec3 towards = vec3(f.x, 0.0, f.y);
    vec3 right = vec3(f.y, 0.0, -f.x);
    vec3 corner = vertex.x * right + vec3(0.0, vertex.y, 0.0);
    corner += instanceDirection(uv5, windInstanceOffset(instanceLocalDirection(uv5, corner), uv4, uv5, world, inverseWorld, false));
    vec4 position = vec4(centre + uv4.w * corner, 1.0);
    gl_Position = mul(worldViewProj, position);
    vUv = uv0;
#ifdef CASTER
    vClipZW = gl_Position.zw;
#else
    mat3 toWorld = toMat3(world);
    vec3 sun = normalize(sunDirection.xyz);
    vSunInQuad = vec3(dot(sun, normalize(mul(toWorld, right))), dot(sun, normalize(mul(toWorld, vec3(0.0, 1.0, 0.0)))),
                      dot(sun, normalize(mul(toWorld, towards))));
#endif
#ifdef SHADOW_RECEIVER
    passShadowPositions(mul(world, position));
#endif
}
