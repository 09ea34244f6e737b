#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#else
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
// Shadow caster: passes clip-space z and w on; the fragment stage writes depth in 0..1.
// INSTANCED: placed by the Forest's instance data first (TreeLodInstance.glsl).
uniform mat4 worldViewProj;

in vec4 vertex;
in vec2 uv0;

out vec2 vClipZW;
out vec2 vUv;
#ifdef INSTANCED
#include "TreeLodInstance.glsl"
#endif

void main()
{
#ifdef INSTANCED
    gl_Position = worldViewProj * instancePosition(vertex);
#else
    gl_Position = worldViewProj * vertex;
#endif
    vClipZW = gl_Position.zw;
    vUv = uv0;
}
