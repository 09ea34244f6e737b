#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#else
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
// The billboard-set floor: the impostor's sRGB colour written as it is (unlit), alpha tested.
uniform sampler2D colourMap;
uniform float alphaCutoff;
in vec2 vUv;
out vec4 fragColour;

void main()
{
    vec4 texel = texture(colourMap, vUv);
    if (texel.a < alphaCutoff)
        discard;
    fragColour = vec4(texel.rgb, 1.0);
}
