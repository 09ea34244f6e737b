#version 330 core
// Shadow caster: depth normalised to 0..1 by the scene depth range.
uniform mat4 worldViewProj;
uniform vec4 depthRange; // near, far, far - near, 1 / (far - near)

in vec4 vertex;
in vec2 uv0;

out float vDepth;
out vec2 vUv;

void main()
{
    gl_Position = worldViewProj * vertex;
    vDepth = (gl_Position.z - depthRange.x) * depthRange.w;
    vUv = uv0;
}
