#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#else
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
// colour = albedo * (ambient * ao + sun * max(0, n.l)) in linear space, written as sRGB
// (LightingSpec in TreeLod/Camera.h; the CPU reference renderer uses the same formula).
// LEAF: alpha test by discard; two-sided, the back side with backColour instead of baseColour.
// SHADOW_RECEIVER: the sun term is scaled by the sun's visibility in the shadow texture.
// AO: the vertex colour's red channel scales the ambient term (bark AO, García et al. 2007 §5.2).
uniform sampler2D diffuseMap;
uniform vec4 sunDirection;  // world space, towards the sun (w = 0 for a directional light)
uniform vec4 sunColour;
uniform vec4 ambientColour;
uniform vec4 baseColour;    // linear
uniform vec4 backColour;    // linear
uniform float alphaCutoff;
uniform float alphaMaxLod;  // coarsest mip level the alpha test reads (see leafAlpha)

in vec3 vNormal;
in vec3 vToCamera;
in vec2 vUv;
#ifdef AO
in float vAo;
#endif

out vec4 fragColour;

#include "TreeLodShading.glsl"
#include "TreeLodLeafAlpha.glsl"

void main()
{
    vec4 texel = texture(diffuseMap, vUv);
#ifdef LEAF
    texel.a = leafAlpha(diffuseMap, vUv, alphaMaxLod);
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
    float lambert = max(dot(n, normalize(sunDirection.xyz)), 0.0) * sunVisibility();
#ifdef AO
    float ao = vAo;
#else
    float ao = 1.0;
#endif
    vec3 colour = albedo * (ambientColour.rgb * ao + sunColour.rgb * lambert);
    fragColour = vec4(toSrgb(colour), 1.0);
}
