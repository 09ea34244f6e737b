#version 330 core
// Ray-ellipsoid intersection in the ellipsoid's unit-sphere frame (Sigg et al. 2006; the
// ellipsoids-and-lines paper (001) §5): the view ray t * dir from the eye (view space origin)
// becomes o + t * k with o = toUnit * (-centre), k = toUnit * dir, and |o + t k| = 1 is a
// quadratic in t. The nearest hit in front of the eye is drawn with its true depth; the normal
// is the unit sphere's u brought back to view space by the inverse transpose, transpose(toUnit).
// colour = albedo * (ambient * ao + sun * max(0, n.l)) in linear space, written as sRGB, as
// TreeLodLit.frag lights the leaves (LightingSpec in TreeLod/Camera.h).
// Not yet here: the paper's noise cube maps (alpha test and normal noise, §3.1 and §5).
uniform mat4 projection;
uniform vec4 sunDirection; // view space, towards the sun (w = 0 for a directional light)
uniform vec4 sunColour;
uniform vec4 ambientColour;

in vec3 vRay;
flat in vec3 vCentre;
flat in mat3 vToUnit;
flat in vec4 vColour;

out vec4 fragColour;

#include "TreeLodShading.glsl"

void main()
{
    vec3 dir = normalize(vRay);
    vec3 o = vToUnit * -vCentre;
    vec3 k = vToUnit * dir;
    float a = dot(k, k), b = dot(o, k), c = dot(o, o) - 1.0;
    float disc = b * b - a * c;
    if (disc < 0.0)
        discard;
    float root = sqrt(disc);
    float t = (-b - root) / a;
    if (t <= 0.0) // the eye is inside: the far side
        t = (-b + root) / a;
    if (t <= 0.0)
        discard;
    vec3 hit = t * dir;
    vec4 clip = projection * vec4(hit, 1.0);
    float ndcDepth = clip.z / clip.w;
    if (ndcDepth < -1.0)
        discard; // before the near plane
    gl_FragDepth = 0.5 * ndcDepth + 0.5;

    vec3 n = normalize(transpose(vToUnit) * (o + t * k));
    if (dot(n, dir) > 0.0) // seen from inside
        n = -n;
    vec3 albedo = toLinear(vColour.rgb);
    float lambert = max(dot(n, normalize(sunDirection.xyz)), 0.0) * sunVisibility();
    vec3 lit = albedo * (ambientColour.rgb * vColour.a + sunColour.rgb * lambert);
    fragColour = vec4(toSrgb(lit), 1.0);
}
