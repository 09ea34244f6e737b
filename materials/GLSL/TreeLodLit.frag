#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#elif defined(OGRE_GLSL)
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
#include "TreeLodTransition.glsl"
// colour = albedo * (ambient * ao + sun * max(0, n.l)) in linear space, written as sRGB
// (LightingSpec in TreeLod/Camera.h; the CPU reference renderer uses the same formula).
// LEAF: alpha test by discard; two-sided, the back side with backColour instead of baseColour.
// SHADOW_RECEIVER: the sun term is scaled by the sun's visibility in the shadow texture.
// AO: the vertex colour's red channel scales the ambient term (bark AO, García et al. 2007 §5.2).
SAMPLER2D(diffuseMap, 0);
uniform vec4 sunDirection;  // world space, towards the sun (w = 0 for a directional light)
uniform vec4 sunColour;
uniform vec4 ambientColour;
uniform vec4 baseColour;    // linear
uniform vec4 backColour;    // linear
uniform float alphaCutoff;
uniform float alphaMaxLod;  // coarsest mip level the alpha test reads (see leafAlpha)

#define SHADOW_UNIT0 1
#define SHADOW_UNIT1 2
#define SHADOW_UNIT2 3
#include "TreeLodShading.glsl"
#include "TreeLodLeafAlpha.glsl"

MAIN_PARAMETERS
    IN(vec3 vNormal, TEXCOORD0)
    IN(vec3 vToCamera, TEXCOORD1)
    IN(vec2 vUv, TEXCOORD2)
#ifdef AO
    IN(float vAo, TEXCOORD3)
#endif
#ifdef SHADOW_RECEIVER
    SHADOW_POSITIONS_IN(TEXCOORD4, TEXCOORD5, TEXCOORD6)
#endif
    TRANSITION_IN(TEXCOORD7)
MAIN_DECLARATION
{
    vec4 texel = TEX2D(diffuseMap, vUv);
#ifdef LEAF
    texel.a = leafAlpha(SAMPLER2D_ARG(diffuseMap), vUv, alphaMaxLod);
#endif
    vec3 n = normalize(vNormal);
    vec3 tint = baseColour.rgb;
#ifdef LEAF
    if (baseColour.a * texel.a < alphaCutoff)
        discard;
    // Facing from the normal, not gl_FrontFacing: render-to-texture flips Y and with it
    // the winding that gl_FrontFacing reports.
    if (dot(n, vToCamera) < 0.0)
    {
        n = -n;
        tint = backColour.rgb;
    }
#endif
    vec3 albedo = tint * toLinear(texel.rgb);
    float lambert = max(dot(n, normalize(sunDirection.xyz)), 0.0) * SUN_VISIBILITY;
#ifdef AO
    float ao = vAo;
#else
    float ao = 1.0;
#endif
    vec3 colour = albedo * (ambientColour.rgb * ao + sunColour.rgb * lambert);
    TRANSITION_DISCARD
    fragColour = vec4(toSrgb(colour), 1.0);
}
