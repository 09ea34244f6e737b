#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#elif defined(OGRE_GLSL)
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
// The billboard-set floor: Ogre's BillboardSet builds the camera-facing quads on the CPU.
uniform mat4 worldViewProj;

MAIN_PARAMETERS
    IN(vec4 vertex, POSITION)
    IN(vec2 uv0, TEXCOORD0)
    OUT(vec2 vUv, TEXCOORD0)
MAIN_DECLARATION
{
    gl_Position = mul(worldViewProj, vertex);
    vUv = uv0;
}
