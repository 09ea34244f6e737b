// Screen-door transitions between two levels of one tree (TreeLod/ForestInstances.h,
// "Transitions"). A tree in a transition band is drawn at both levels with complementary codes:
// 0 keeps every pixel, f in (0, 1] the pixels whose threshold is below f (the coarse level's share),
// -f the others (the fine level's rest), so the two draws cover what one covers, without blending
// or sorting; shadow casters use the same masks in the shadow texture.
// The threshold is an 8x8 Bayer matrix in window pixels (Bayer 1973), shifted per tree by a hash
// of its position (a multiple of 1/64, so the shares stay exact) so that trees one behind another
// in a transition do not drop the same pixels.
// Vertex programs: TRANSITION_OUT(semantic) last among their outputs, and vTransition =
// transitionOf(uv4, uv5) (the instance data, TreeLodInstance.glsl), objectTransition.xy (a tree
// object's draw: `uniform vec4 objectTransition`, the Renderable's custom parameter 7,
// TreeLod/ObjectTransition.h), drawTransition (either) or NO_TRANSITION.
// Fragment programs: TRANSITION_IN(semantic) last among their inputs, and TRANSITION_DISCARD
// before their output, after their derivatives and implicit-LOD samples.
#define TRANSITION_OUT(semantic) FLAT_OUT(vec2 vTransition, semantic)
#define TRANSITION_IN(semantic) FLAT_IN(vec2 vTransition, semantic)
#define NO_TRANSITION vec2_splat(0.0)
#define TRANSITION_DISCARD if (transitionDrops(gl_FragCoord.xy, vTransition)) discard;

/// (code, pattern shift) of an instance: the code is uv5.z (0 where the data has no third value);
/// the shift hashes the instance's quarter-metre cell in integers, so that the two programs of a
/// transition (each compiled on its own, with its own float contractions) get the same shift
/// (TreeLod::transitionPatternShift computes it for tree objects).
vec2 transitionOf(vec4 uv4, vec3 uv5)
{
    ivec3 cell = ivec3(floor(uv4.xyz * 4.0)) + ivec3_splat(16777216); // positive within 4000 km
    uint hash = (uint(cell.x) * 73856093u) ^ (uint(cell.y) * 19349663u) ^ (uint(cell.z) * 83492791u);
    return vec2(uv5.z, float(hash & 63u) / 64.0);
}

/// The code and shift of a draw by a program that the Forest's batches and the tree objects share:
/// the instance's where it carries a code, else the Renderable's (both set it, (0, 0) by default).
vec2 drawTransition(vec4 uv4, vec3 uv5, vec4 objectTransition)
{
    return uv5.z != 0.0 ? transitionOf(uv4, uv5) : objectTransition.xy;
}

/// The coarse level's share at `sizeRatio` (screen size over the switch's) in a band ending at
/// `end`; 0 outside it (TreeLod::transitionCoarseShare).
float transitionCoarseShare(float sizeRatio, float end)
{
    return end > 1.0 && sizeRatio < end ? min((end - sizeRatio) / (end - 1.0), 1.0) : 0.0;
}

/// The 8x8 Bayer threshold of a window pixel, in (0, 1): M8 = 16 M2(p) + 4 M2(p / 2) + M2(p / 4),
/// with M2(x, y) = (2x + 3y) mod 4 the 2x2 matrix ((0, 2), (3, 1)).
float transitionThreshold(vec2 fragCoord)
{
    vec2 p = floor(fragCoord);
    p -= 8.0 * floor(p / 8.0);
    vec2 a = p - 2.0 * floor(p / 2.0);
    vec2 b = floor(p / 2.0) - 2.0 * floor(p / 4.0);
    vec2 c = floor(p / 4.0);
    vec3 m = vec3(2.0 * a.x + 3.0 * a.y, 2.0 * b.x + 3.0 * b.y, 2.0 * c.x + 3.0 * c.y);
    m -= 4.0 * floor(m / 4.0);
    return (dot(m, vec3(16.0, 4.0, 1.0)) + 0.5) / 64.0;
}

/// Whether this draw leaves the pixel to the tree's other level (TreeLod::transitionKeeps negated).
bool transitionDrops(vec2 fragCoord, vec2 transition)
{
    float threshold = fract(transitionThreshold(fragCoord) + transition.y);
    return transition.x > 0.0 ? threshold >= transition.x : threshold < -transition.x;
}
