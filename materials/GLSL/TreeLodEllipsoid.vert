#version 330 core
// Ellipsoids of an EllipsoidTree (EllipsoidTreeData.h), ray cast per fragment (Sigg et al. 2006,
// as the ellipsoids-and-lines paper (001) §5 renders them): one quad per ellipsoid that covers
// its bounding sphere as the camera sees it; the fragment stage intersects the view ray with
// the ellipsoid in the frame where it is the unit sphere.
// Per vertex: vertex = the centre (tree space, metres), uv0 = the quad corner (+-1, +-1),
// uv1..uv3 = the three semi-axes (rotation columns times radii times the level's scale),
// colour = sRGB colour, alpha = ambient occlusion. Per instance (TreeLodInstance.glsl): uv4, uv5.
uniform mat4 worldView;
uniform mat4 projection;
uniform float nearClip;

in vec4 vertex;
in vec2 uv0;
in vec3 uv1;
in vec3 uv2;
in vec3 uv3;
in vec4 colour;

#include "TreeLodInstance.glsl"

out vec3 vRay;         // the quad point in view space: the view ray's direction
flat out vec3 vCentre; // view space
flat out mat3 vToUnit; // view space -> the unit-sphere frame (about the centre)
flat out vec4 vColour;

void main()
{
    vec3 centre = (worldView * instancePosition(vec4(vertex.xyz, 1.0))).xyz;
    mat3 toView = mat3(worldView);
    mat3 axes = mat3(toView * instanceDirection(uv4.w * uv1), toView * instanceDirection(uv4.w * uv2),
                     toView * instanceDirection(uv4.w * uv3));
    float radius = max(length(axes[0]), max(length(axes[1]), length(axes[2])));
    float d = length(centre);
    vec3 forward, right, up;
    float at, extent;
    if (d > 1.001 * radius + nearClip)
    {
        // The cone from the eye around the sphere, cut at its nearest point.
        forward = centre / d;
        at = d - radius;
        extent = at * radius / sqrt(d * d - radius * radius);
    }
    else
    {
        // The eye is inside or at the bounding sphere: a quad just past the near plane covering the view.
        forward = vec3(0.0, 0.0, -1.0);
        at = 1.01 * nearClip;
        extent = 1000.0 * at;
    }
    right = normalize(abs(forward.y) < 0.99 ? cross(forward, vec3(0.0, 1.0, 0.0)) : cross(forward, vec3(1.0, 0.0, 0.0)));
    up = cross(right, forward);
    vRay = at * forward + extent * (uv0.x * right + uv0.y * up);
    vCentre = centre;
    vToUnit = inverse(axes);
    vColour = colour;
    gl_Position = projection * vec4(vRay, 1.0);
}
