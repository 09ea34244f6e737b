#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#else
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
// The billboard-set floor: Ogre's BillboardSet builds the camera-facing quads on the CPU.
uniform mat4 worldViewProj;
in vec4 vertex;
in vec2 uv0;
out vec2 vUv;

void main()
{
    gl_Position = worldViewProj * vertex;
    vUv = uv0;
}
