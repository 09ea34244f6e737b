// The Forest's per-instance data (TreeLod/Forest.h), for vertex programs built with INSTANCED:
// the tree's local space -> the Forest's local space, p' = R_y * (s * p) + t, with R_y the
// right-handed rotation about +Y of ForestInstances' matrices: x' = c x + s z, z' = -s x + c z.
// The Renderable's world matrix (the Forest's node) applies after it, as for any object.
// INSTANCE_IN goes in main's parameters: uv4 = position xyz, uniform scale; uv5 = cos, sin of the
// rotation about +Y, and the transition code (TreeLodTransition.glsl; 0, as GL reads a missing third
// value, draws the whole tree).
#define INSTANCE_IN IN(vec4 uv4, TEXCOORD4) IN(vec3 uv5, TEXCOORD5)

/// A direction (normal, tangent) turned like the instance; the uniform scale leaves it alone.
vec3 instanceDirection(vec3 uv5, vec3 v)
{
    return vec3(uv5.x * v.x + uv5.y * v.z, v.y, -uv5.y * v.x + uv5.x * v.z);
}

/// The inverse of instanceDirection: a Forest-local direction in the tree's local frame.
vec3 instanceLocalDirection(vec3 uv5, vec3 v)
{
    return vec3(uv5.x * v.x - uv5.y * v.z, v.y, uv5.y * v.x + uv5.x * v.z);
}

/// A point (w = 1) placed like the instance.
vec4 instancePosition(vec4 uv4, vec3 uv5, vec4 p)
{
    return vec4(instanceDirection(uv5, uv4.w * p.xyz) + uv4.xyz, 1.0);
}
