#if defined(OGRE_GLSLES)
#version 300 es
#elif OGRE_GLSL >= 330
#version 330 core
#elif defined(OGRE_GLSL)
#version 150
#endif
#include "TreeLodShaderSupport.glsl"
#include "TreeLodTransition.glsl"
// Lines of an EllipsoidTree (EllipsoidLineData.h: capsules, a segment swept by a sphere), ray cast
// per fragment like the ellipsoids (TreeLodEllipsoid.frag). The paper (001, §5) draws its lines as
// screen-aligned strips ([MSE*06]); here the strip is a quad along the segment, turned to face the
// projection's centre (the eye, or the view direction of an orthographic shadow camera), its ends
// pushed out and its sides out by the radius, and never narrower than one pixel: §6 draws levels
// whose mean line is 1 px wide, so twigs are thinner than a pixel and the fragment program gives
// them the pixel's width as a line rasteriser would.
// Per vertex: vertex = start (tree space, metres), uv0 = corner (x: 0 start, 1 end; y: -1, +1
// across), uv1 = end xyz and radius, colour = sRGB colour, alpha = ambient occlusion. Per instance
// (TreeLodInstance.glsl): uv4, uv5. Wind (TreeLodWind.glsl): each end moves with the mesh's points
// there (a skinned segment).
uniform mat4 world;
uniform mat4 inverseWorld;
uniform mat4 worldView;
uniform mat4 projection;
uniform mat4 inverseProjection;
uniform vec4 viewportSize; // width, height, 1 / width, 1 / height
uniform vec4 objectTransition; // custom 7 (TreeLod/ObjectTransition.h)

#include "TreeLodInstance.glsl"
#include "TreeLodWind.glsl"

// The projection's centre (w = 1) or, for a parallel projection, its direction (w = 0).
vec4 projectionCentre()
{
    vec4 c = mul(inverseProjection, vec4(0.0, 0.0, 1.0, 0.0));
    return abs(c.w) > 1e-9 * length(c.xyz) ? vec4(c.xyz / c.w, 1.0) : vec4(normalize(c.xyz), 0.0);
}

MAIN_PARAMETERS
    IN(vec4 vertex, POSITION)
    IN(vec2 uv0, TEXCOORD0)
    IN(vec4 uv1, TEXCOORD1)
    IN(vec4 colour, COLOR)
    INSTANCE_IN
    OUT(vec3 vPosition, TEXCOORD0)     // view space: the quad's point, on the pixel's ray
    FLAT_OUT(vec3 vStart, TEXCOORD1)   // view space
    FLAT_OUT(vec3 vEnd, TEXCOORD2)
    FLAT_OUT(float vRadius, TEXCOORD3)
    FLAT_OUT(float vPixel, TEXCOORD4)  // view-space size of a pixel at the line (perspective: at its nearer end)
    FLAT_OUT(vec4 vColour, TEXCOORD5)
    FLAT_OUT(vec4 vProjectionCentre, TEXCOORD6) // projectionCentre(), for the fragment's ray
    TRANSITION_OUT(TEXCOORD7)
MAIN_DECLARATION
{
    vTransition = drawTransition(uv4, uv5, objectTransition);
    vec3 start = vertex.xyz + windInstanceOffset(vertex.xyz, uv4, uv5, world, inverseWorld, false);
    vec3 end = uv1.xyz + windInstanceOffset(uv1.xyz, uv4, uv5, world, inverseWorld, false);
    vec3 a = mul(worldView, instancePosition(uv4, uv5, vec4(start, 1.0))).xyz;
    vec3 b = mul(worldView, instancePosition(uv4, uv5, vec4(end, 1.0))).xyz;
    float radius = uv1.w * uv4.w;
    vec4 centre = projectionCentre();
    vec3 p = mix(a, b, uv0.x);
    vec3 sight = centre.w > 0.0 ? p - centre.xyz : centre.xyz;
    // A pixel's size at p: the projection's scale on y at p's distance along the sight line.
    float distance = centre.w > 0.0 ? max(length(sight), 1e-6) : 1.0;
    vPixel = 2.0 * distance * viewportSize.w / max(abs(projection[1][1]), 1e-9);
    sight = normalize(sight);
    vec3 axis = b - a;
    float len = length(axis);
    axis = len > 1e-9 ? axis / len : vec3(0.0, 1.0, 0.0);
    vec3 across = cross(axis, sight);
    if (length(across) < 1e-3) // seen end on: any two directions across the sight line
    {
        across = cross(abs(sight.y) < 0.99 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0), sight);
        axis = cross(sight, normalize(across));
    }
    across = normalize(across);
    float reach = max(1.05 * radius, vPixel);
    vPosition = p + across * (reach * uv0.y) + axis * (reach * (2.0 * uv0.x - 1.0));
    vStart = a;
    vEnd = b;
    vRadius = radius;
    vColour = colour;
    vProjectionCentre = centre;
    gl_Position = mul(projection, vec4(vPosition, 1.0));
}
