#version 330 core
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
