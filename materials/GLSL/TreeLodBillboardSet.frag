#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#elif defined(OGRE_GLSL)
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
// The billboard-set floor: the impostor's sRGB colour written as it is (unlit), alpha tested.
SAMPLER2D(colourMap, 0);
uniform float alphaCutoff;

MAIN_PARAMETERS
    IN(vec2 vUv, TEXCOORD0)
MAIN_DECLARATION
{
    vec4 texel = TEX2D(colourMap, vUv);
    if (texel.a < alphaCutoff)
        discard;
    fragColour = vec4(texel.rgb, 1.0);
}
