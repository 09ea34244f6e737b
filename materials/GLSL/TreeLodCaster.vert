#version 330 core
// Shadow caster: passes clip-space z and w on; the fragment stage writes depth in 0..1.
uniform mat4 worldViewProj;

in vec4 vertex;
in vec2 uv0;

out vec2 vClipZW;
out vec2 vUv;

void main()
{
    gl_Position = worldViewProj * vertex;
    vClipZW = gl_Position.zw;
    vUv = uv0;
}
