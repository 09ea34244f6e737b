// The wind (TreeLod/WindModel.h: the model, its terms and its deviation; the CPU side computes the
// same, term for term). Uniforms: windDirection, windPhase and windShape come from the shared
// parameter set "TreeLod/Wind" (TreeLod/Wind.h) in every program's default_params; windTree is
// each Renderable's custom parameter 12, the tree's height in its own units (0: no wind).
uniform vec4 windDirection; // world x, 0, z (unit), strength S
uniform vec4 windPhase;     // gust, sway, branch, leaf phases in [0, 2 pi)
uniform vec4 windShape;     // gustiness G, gust wavenumber k (rad per metre), 0, 0
uniform vec4 windTree;      // custom 12: tree height H (its own units), 0, 0, 0

#define WIND_TWO_PI 6.283185307179586

/// The wind's direction in an object's frame, from the world's (`inverseWorld`: the object's
/// inverse world matrix); zero when calm.
vec3 windAlongObject(mat4 inverseWorld)
{
    vec3 along = mul(toMat3(inverseWorld), vec3(windDirection.x, 0.0, windDirection.z));
    along.y = 0.0;
    float len = length(along);
    return len > 0.0 ? along / len : vec3(0.0, 0.0, 0.0);
}

/// The offset of `p` (the tree's frame: y up, base at the origin) of the tree standing at
/// `treeBase` (world), the wind blowing `along` (the tree's frame, unit). LEAF adds flutter.
vec3 windOffset(vec3 p, vec3 along, vec3 treeBase, bool leaf)
{
    float height = windTree.x;
    if (!(height > 0.0) || windDirection.w == 0.0)
        return vec3(0.0, 0.0, 0.0);
    vec2 base = treeBase.xz;
    float force = windDirection.w * (1.0 + windShape.x * sin(windPhase.x - windShape.y * dot(base, windDirection.xz)));
    float treePhase = WIND_TWO_PI * fract(dot(base, vec2(0.1031, 0.0717)));
    float eta = clamp(p.y / height, 0.0, 1.0);

    float bend = 0.12 * tanh(force / 2.0) * (1.0 + 0.25 * sin(windPhase.y + treePhase));
    vec3 result = along * (height * bend * eta * eta);
    result.y -= (2.0 / 3.0) * height * bend * bend * eta * eta * eta;

    float rho = clamp(length(p.xz) / (0.5 * height), 0.0, 1.0);
    float sway = 0.03 * height * tanh(force / 1.5) * rho * eta;
    float branchPhase = windPhase.z + treePhase + WIND_TWO_PI * dot(p / height, vec3(0.9, 0.7, 1.1));
    result += sway * (along * sin(branchPhase) + vec3(0.0, 0.5 * cos(branchPhase), 0.0));

    if (leaf)
    {
        float flutter = 0.004 * height * tanh(force) * eta;
        float leafPhase = windPhase.w + WIND_TWO_PI * fract(dot(p / height, vec3(13.1, 17.3, 11.7)));
        result.y += flutter * sin(leafPhase);
    }
    return result;
}

/// The offset of `p` (object space) of a tree drawn alone: its object frame is the tree's frame.
/// `leaf`: a leaf vertex of the mesh or LoDF (flutter).
vec3 windObjectOffset(vec3 p, mat4 world, mat4 inverseWorld, bool leaf)
{
    vec3 treeBase = mul(world, vec4(0.0, 0.0, 0.0, 1.0)).xyz;
    return windOffset(p, windAlongObject(inverseWorld), treeBase, leaf);
}

#ifdef INSTANCE_IN
/// The offset of `p` (the tree's frame) of a Forest instance (TreeLodInstance.glsl), in the tree's
/// frame: instancePosition places p + offset.
vec3 windInstanceOffset(vec3 p, vec4 uv4, vec3 uv5, mat4 world, mat4 inverseWorld, bool leaf)
{
    vec3 treeBase = mul(world, vec4(uv4.xyz, 1.0)).xyz;
    return windOffset(p, instanceLocalDirection(uv5, windAlongObject(inverseWorld)), treeBase, leaf);
}
#endif
