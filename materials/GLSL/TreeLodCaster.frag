#version 330 core
// Shadow caster; ALPHA_TEST: leaves cast the shadow of their texture's shape.
#ifdef ALPHA_TEST
uniform sampler2D diffuseMap;
uniform float alphaCutoff;
#endif

in float vDepth;
in vec2 vUv;

out vec4 fragColour;

void main()
{
#ifdef ALPHA_TEST
    if (texture(diffuseMap, vUv).a < alphaCutoff)
        discard;
#endif
    fragColour = vec4(vDepth, vDepth, vDepth, 1.0);
}
