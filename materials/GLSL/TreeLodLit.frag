#version 330 core
// colour = albedo * (ambient + sun * max(0, n.l)) in linear space, written as sRGB
// (LightingSpec in TreeLod/Camera.h; the CPU reference renderer uses the same formula).
// LEAF: alpha test by discard; two-sided, the back side with backColour instead of baseColour.
uniform sampler2D diffuseMap;
uniform vec4 sunDirection;  // world space, towards the sun (w = 0 for a directional light)
uniform vec4 sunColour;
uniform vec4 ambientColour;
uniform vec4 baseColour;    // linear
uniform vec4 backColour;    // linear
uniform float alphaCutoff;

in vec3 vNormal;
in vec3 vToCamera;
in vec2 vUv;

out vec4 fragColour;

vec3 toLinear(vec3 c) { return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(0.04045, c)); }
vec3 toSrgb(vec3 c)
{
    c = clamp(c, 0.0, 1.0);
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}

void main()
{
    vec4 texel = texture(diffuseMap, vUv);
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
    float lambert = max(dot(n, normalize(sunDirection.xyz)), 0.0);
    vec3 colour = albedo * (ambientColour.rgb + sunColour.rgb * lambert);
    fragColour = vec4(toSrgb(colour), 1.0);
}
