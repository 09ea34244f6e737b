// Procedural trees after Weber & Penn, "Creation and Rendering of Realistic Trees"
// (SIGGRAPH 1995), written from the paper's description (W&P below).
//
// What follows the paper: recursive stems with per-level parameters (length and length
// variation, curve resolution, curve / curve back / curve variation, down angle with its
// variation (negative variation = varies with the position on the parent), rotate
// (phyllotaxis; negative = alternating), branches per stem), the shape ratio table for
// first-level lengths, child length and radius rules (RatioPower), linear taper, trunk
// flare, attraction up, leaves on the last stem level weighted by ShapeRatio(4, ...).
// Deviations: no stem splits (SegSplits) and no pruning envelope; several trunks from the
// ground (shrub) instead of BaseSplits; attraction up is a simpler rotation towards (or away
// from) +Y by a fraction of the declination, per level; the leaf count is exact (rounded
// cumulative weights over the leaf-bearing stems) and leaves are placed around those stems
// on invisible twigs instead of on a further stem level; the tree is scaled so that the top
// of its stems is exactly the requested height.
#include "TreeLod/TreeGenerator.h"

#include "TreeLod/LeafTexture.h"

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

namespace TreeLod
{
    namespace
    {
        constexpr std::uint32_t kMinLeaves = 100;
        constexpr std::uint32_t kMaxLeaves = 200000;


        /// Portable random numbers: std::mt19937 is specified bit for bit, the std
        /// distributions are not, so the mapping to floats is our own.
        class Random
        {
        public:
            explicit Random(std::uint32_t seed) : mEngine(seed) {}

            /// Uniform in [0, 1), 24 bits.
            float unit() { return float(mEngine() >> 8) * (1.0f / 16777216.0f); }
            float range(float lo, float hi) { return lo + (hi - lo) * unit(); }
            /// W&P's random(v): uniform in [-v, v].
            float spread(float v) { return range(-v, v); }

        private:
            std::mt19937 mEngine;
        };

        /// Independent seeds for independent streams (splitmix64 finaliser).
        std::uint32_t mixSeed(std::uint32_t a, std::uint32_t b)
        {
            std::uint64_t x = (std::uint64_t(a) << 32) ^ b ^ 0x9E3779B97F4A7C15ull;
            x ^= x >> 30;
            x *= 0xBF58476D1CE4E5B9ull;
            x ^= x >> 27;
            x *= 0x94D049BB133111EBull;
            x ^= x >> 31;
            return std::uint32_t(x ^ (x >> 32));
        }

        /// Rodrigues rotation of v about the unit axis.
        glm::vec3 rotateAbout(const glm::vec3& v, const glm::vec3& axis, float angle)
        {
            const float c = std::cos(angle), s = std::sin(angle);
            return v * c + glm::cross(axis, v) * s + axis * (glm::dot(axis, v) * (1.0f - c));
        }

        /// Orthonormal, right-handed stem frame; z is the growth direction.
        struct Frame
        {
            glm::vec3 x{1.0f, 0.0f, 0.0f};
            glm::vec3 y{0.0f, 0.0f, -1.0f};
            glm::vec3 z{0.0f, 1.0f, 0.0f};
        };

        Frame rotateFrame(const Frame& f, const glm::vec3& axis, float angle)
        {
            return {rotateAbout(f.x, axis, angle), rotateAbout(f.y, axis, angle), rotateAbout(f.z, axis, angle)};
        }

        Frame orthonormalise(Frame f)
        {
            f.z = glm::normalize(f.z);
            f.x = glm::normalize(f.x - f.z * glm::dot(f.x, f.z));
            f.y = glm::cross(f.z, f.x);
            return f;
        }

        /// W&P shape ratio table: envelope of first-level branch lengths along the trunk.
        enum Shape
        {
            Conical,
            Spherical,
            Hemispherical,
            Cylindrical,
            TaperedCylindrical,
            Flame,
            InverseConical,
            TendFlame
        };

        float shapeRatio(Shape shape, float r)
        {
            r = std::clamp(r, 0.0f, 1.0f);
            switch (shape)
            {
            case Conical: return 0.2f + 0.8f * r;
            case Spherical: return 0.2f + 0.8f * std::sin(glm::pi<float>() * r);
            case Hemispherical: return 0.2f + 0.8f * std::sin(0.5f * glm::pi<float>() * r);
            case Cylindrical: return 1.0f;
            case TaperedCylindrical: return 0.5f + 0.5f * r;
            case Flame: return r <= 0.7f ? r / 0.7f : (1.0f - r) / 0.3f;
            case InverseConical: return 1.0f - 0.8f * r;
            case TendFlame: return r <= 0.7f ? 0.5f + 0.5f * r / 0.7f : 0.5f + 0.5f * (1.0f - r) / 0.3f;
            }
            return 1.0f;
        }

        /// W&P per-level parameters ("nLength", "nCurve", ...). Angles in degrees.
        /// Level n's values describe level-n stems; `branches` is how many of them one
        /// level n-1 stem carries (scaled by W&P's length rule below level 1).
        struct LevelParams
        {
            float length = 1.0f, lengthV = 0.0f; ///< level 0: relative to the height; else to the parent
            int curveRes = 3;                    ///< segments per stem
            float curve = 0.0f, curveBack = 0.0f, curveV = 0.0f; ///< + bends towards the stem's -y
            float downAngle = 45.0f, downAngleV = 0.0f;
            float rotate = 137.5f, rotateV = 0.0f; ///< < 0: alternate sides, |rotate| off the parent's x
            int branches = 0;
            float start = 0.0f;      ///< fraction of the parent bare of these stems (level 1: baseSize)
            float taper = 1.0f;      ///< 0 = cylinder, 1 = cone
            float attractionUp = 0.0f; ///< per stem, fraction of the declination (- = droop)
            int sides = 6;           ///< bark ring vertices
        };

        struct PresetParams
        {
            float height = 10.0f;
            std::uint32_t leaves = 5000;
            int levels = 3; ///< stem levels; leaves on the last
            Shape shape = Hemispherical;
            float baseSize = 0.2f;  ///< fraction of the trunk bare of branches
            float ratio = 0.02f;    ///< trunk radius / trunk length
            float ratioPower = 1.3f;
            float flare = 0.5f;
            int trunks = 1;
            float trunkLeanMin = 0.0f, trunkLeanMax = 0.0f; ///< degrees from vertical
            float trunkBaseSpread = 0.0f; ///< trunk bases scattered within this fraction of the height
            std::array<LevelParams, 3> level;
            // leaves
            float leafAreaFactor = 1.0f; ///< total quad area = factor * height^2
            float leafSpread = 0.03f;    ///< reach of leaves around their stem, fraction of the height
            float leafStart = 0.2f;      ///< leaves on this outer fraction of a stem onwards
            float leafDownAngle = 50.0f, leafDownAngleV = 20.0f;
            float leafBend = 0.4f;       ///< + turns leaf axes up, - lets them hang
            float leafFaceUp = 0.8f;     ///< 1: leaves face the sky, 0: face outwards
            float leafTwistV = 30.0f;    ///< random roll about the leaf axis, degrees
        };

        PresetParams presetParams(TreePreset preset)
        {
            PresetParams p;
            switch (preset)
            {
            case TreePreset::Oak:
            {
                // Decurrent broadleaf: short clear bole, dome crown, branches spreading
                // near horizontal at the bottom, bending up.
                p.height = 12.0f;
                p.leaves = 6000;
                p.shape = Hemispherical;
                p.baseSize = 0.22f;
                p.ratio = 0.028f;
                p.ratioPower = 1.3f;
                p.flare = 0.7f;
                LevelParams& t = p.level[0];
                t.curveRes = 10;
                t.curveV = 25.0f;
                t.taper = 1.0f;
                t.sides = 12;
                LevelParams& b = p.level[1];
                b.length = 0.7f;
                b.lengthV = 0.1f;
                b.curveRes = 6;
                b.curve = -45.0f;
                b.curveV = 70.0f;
                b.downAngle = 66.0f;
                b.downAngleV = -25.0f;
                b.rotate = 137.5f;
                b.rotateV = 20.0f;
                b.branches = 28;
                b.taper = 1.0f;
                b.attractionUp = 0.15f;
                b.sides = 8;
                LevelParams& c = p.level[2];
                c.length = 0.45f;
                c.lengthV = 0.12f;
                c.curveRes = 4;
                c.curve = -10.0f;
                c.curveV = 80.0f;
                c.downAngle = 48.0f;
                c.downAngleV = 18.0f;
                c.rotate = 137.5f;
                c.rotateV = 30.0f;
                c.branches = 14;
                c.start = 0.1f;
                c.taper = 1.0f;
                c.attractionUp = 0.3f;
                c.sides = 5;
                p.leafAreaFactor = 4.0f;
                p.leafSpread = 0.08f;
                p.leafStart = 0.15f;
                p.leafDownAngle = 55.0f;
                p.leafDownAngleV = 25.0f;
                p.leafBend = 0.3f;
                p.leafFaceUp = 0.7f;
                break;
            }
            case TreePreset::Conifer:
            {
                // Excurrent, conical: the trunk runs to the tip; many near-horizontal
                // branches, longest at the bottom (W&P conical shape), twigs in the
                // branch plane (alternating rotate), needle sprays lying flat.
                p.height = 16.0f;
                p.leaves = 10000;
                p.shape = Conical;
                p.baseSize = 0.14f;
                p.ratio = 0.016f;
                p.ratioPower = 1.2f;
                p.flare = 0.4f;
                LevelParams& t = p.level[0];
                t.curveRes = 12;
                t.curveV = 8.0f;
                t.taper = 1.0f;
                t.sides = 10;
                LevelParams& b = p.level[1];
                b.length = 0.3f;
                b.lengthV = 0.04f;
                b.curveRes = 5;
                b.curve = 15.0f;
                b.curveBack = -30.0f;
                b.curveV = 20.0f;
                b.downAngle = 70.0f;
                b.downAngleV = -20.0f;
                b.rotate = 137.5f;
                b.rotateV = 12.0f;
                b.branches = 80;
                b.taper = 1.0f;
                b.sides = 6;
                LevelParams& c = p.level[2];
                c.length = 0.32f;
                c.lengthV = 0.06f;
                c.curveRes = 3;
                c.curve = 10.0f;
                c.curveV = 25.0f;
                c.downAngle = 55.0f;
                c.downAngleV = 12.0f;
                c.rotate = -90.0f;
                c.rotateV = 20.0f;
                c.branches = 12;
                c.start = 0.08f;
                c.taper = 1.0f;
                c.sides = 3;
                p.leafAreaFactor = 3.0f;
                p.leafSpread = 0.03f;
                p.leafStart = 0.05f;
                p.leafDownAngle = 25.0f;
                p.leafDownAngleV = 15.0f;
                p.leafBend = 0.0f;
                p.leafFaceUp = 0.9f;
                p.leafTwistV = 20.0f;
                break;
            }
            case TreePreset::Birch:
            {
                // Slender trunk to the top, narrow ovoid crown, branches rising then
                // arching over, long twigs hanging down (negative attraction).
                p.height = 15.0f;
                p.leaves = 6000;
                p.shape = TendFlame;
                p.baseSize = 0.3f;
                p.ratio = 0.014f;
                p.ratioPower = 1.4f;
                p.flare = 0.3f;
                LevelParams& t = p.level[0];
                t.curveRes = 12;
                t.curveV = 14.0f;
                t.taper = 1.0f;
                t.sides = 10;
                LevelParams& b = p.level[1];
                b.length = 0.3f;
                b.lengthV = 0.06f;
                b.curveRes = 6;
                b.curve = -20.0f;
                b.curveBack = 45.0f;
                b.curveV = 40.0f;
                b.downAngle = 42.0f;
                b.downAngleV = -12.0f;
                b.rotate = 137.5f;
                b.rotateV = 20.0f;
                b.branches = 36;
                b.taper = 1.0f;
                b.sides = 6;
                LevelParams& c = p.level[2];
                c.length = 0.55f;
                c.lengthV = 0.12f;
                c.curveRes = 5;
                c.curve = 20.0f;
                c.curveV = 30.0f;
                c.downAngle = 35.0f;
                c.downAngleV = 15.0f;
                c.rotate = 137.5f;
                c.rotateV = 30.0f;
                c.branches = 10;
                c.start = 0.15f;
                c.taper = 1.0f;
                c.attractionUp = -0.7f;
                c.sides = 4;
                p.leafAreaFactor = 1.0f;
                p.leafSpread = 0.04f;
                p.leafStart = 0.2f;
                p.leafDownAngle = 40.0f;
                p.leafDownAngleV = 20.0f;
                p.leafBend = -0.5f;
                p.leafFaceUp = 0.4f;
                break;
            }
            case TreePreset::Shrub:
            {
                // Many stems from the ground leaning outwards, a low rounded bush.
                p.height = 2.5f;
                p.leaves = 3000;
                p.shape = Spherical;
                p.baseSize = 0.12f;
                p.ratio = 0.015f;
                p.ratioPower = 1.2f;
                p.flare = 0.0f;
                p.trunks = 9;
                p.trunkLeanMin = 12.0f;
                p.trunkLeanMax = 42.0f;
                p.trunkBaseSpread = 0.06f;
                LevelParams& t = p.level[0];
                t.length = 1.0f;
                t.lengthV = 0.25f;
                t.curveRes = 6;
                t.curve = -25.0f;
                t.curveV = 30.0f;
                t.taper = 1.0f;
                t.sides = 6;
                LevelParams& b = p.level[1];
                b.length = 0.42f;
                b.lengthV = 0.1f;
                b.curveRes = 4;
                b.curve = -20.0f;
                b.curveV = 50.0f;
                b.downAngle = 50.0f;
                b.downAngleV = 15.0f;
                b.rotate = 137.5f;
                b.rotateV = 25.0f;
                b.branches = 9;
                b.taper = 1.0f;
                b.sides = 4;
                LevelParams& c = p.level[2];
                c.length = 0.5f;
                c.lengthV = 0.12f;
                c.curveRes = 3;
                c.curveV = 50.0f;
                c.downAngle = 45.0f;
                c.downAngleV = 15.0f;
                c.rotate = 137.5f;
                c.rotateV = 30.0f;
                c.branches = 6;
                c.start = 0.1f;
                c.taper = 1.0f;
                c.attractionUp = 0.2f;
                c.sides = 3;
                p.leafAreaFactor = 3.0f;
                p.leafSpread = 0.1f;
                p.leafStart = 0.1f;
                p.leafDownAngle = 50.0f;
                p.leafDownAngleV = 25.0f;
                p.leafBend = 0.3f;
                p.leafFaceUp = 0.6f;
                break;
            }
            }
            return p;
        }

        struct Stem
        {
            int level = 0;
            int parent = -1;
            float offset = 0.0f; ///< metres along the parent where it starts
            float length = 0.0f;
            float radius = 0.0f; ///< at the base, before flare
            float taper = 1.0f;
            std::vector<glm::vec3> points; ///< curveRes + 1
            std::vector<Frame> segments;   ///< one frame per segment
            std::vector<float> radii;      ///< per point (flare included)
            std::int32_t firstNode = 0;    ///< skeleton index of points[0]

            int segmentAt(float t) const
            {
                const int n = int(segments.size());
                return std::clamp(int(t * float(n)), 0, n - 1);
            }
            glm::vec3 pointAt(float t) const
            {
                const int i = segmentAt(t);
                const float f = std::clamp(t * float(segments.size()) - float(i), 0.0f, 1.0f);
                return points[i] + (points[i + 1] - points[i]) * f;
            }
            float radiusAt(float t) const { return radius * (1.0f - taper * std::clamp(t, 0.0f, 1.0f)); }
            /// Ring orientation at point i: the mean of the adjoining segment frames.
            Frame ringFrame(std::size_t i) const
            {
                if (i == 0)
                    return segments.front();
                if (i >= segments.size())
                    return segments.back();
                Frame f;
                f.x = segments[i - 1].x + segments[i].x;
                f.z = segments[i - 1].z + segments[i].z;
                return orthonormalise(f);
            }
        };

        /// W&P trunk flare: radius multiplier near the base (z = fraction of the trunk).
        float flareAt(float flare, float z)
        {
            const float y = std::max(0.0f, 1.0f - 8.0f * z);
            return 1.0f + flare * (std::pow(100.0f, y) - 1.0f) / 100.0f;
        }

        /// Grow a stem from `start` along `frame` (W&P curvature): each segment turns by
        /// curve/curveRes (or curve and curveBack over the two halves) about the stem's x
        /// axis plus a random curveV/curveRes; we add half that at random about y so that
        /// stems are not planar, then apply attraction up.
        void growStem(Stem& stem, const glm::vec3& start, Frame frame, const LevelParams& lp, float flare, Random& rnd)
        {
            const int n = std::max(1, lp.curveRes);
            const float segLength = stem.length / float(n);
            stem.points.assign(1, start);
            stem.segments.clear();
            const glm::vec3 up(0.0f, 1.0f, 0.0f);
            for (int i = 0; i < n; ++i)
            {
                float bend;
                if (lp.curveBack == 0.0f || n < 2)
                    bend = lp.curve / float(n);
                else
                {
                    const int half = (n + 1) / 2;
                    bend = i < half ? lp.curve / float(half) : lp.curveBack / float(n - half);
                }
                bend += rnd.spread(lp.curveV) / float(n);
                const float sideways = 0.5f * rnd.spread(lp.curveV) / float(n);
                if (stem.level > 0 || i > 0) // the trunk leaves the ground as planted
                {
                    frame = rotateFrame(frame, frame.x, glm::radians(bend));
                    frame = rotateFrame(frame, frame.y, glm::radians(sideways));
                }
                if (lp.attractionUp != 0.0f)
                {
                    const float declination = std::acos(std::clamp(glm::dot(frame.z, up), -1.0f, 1.0f));
                    glm::vec3 axis = glm::cross(frame.z, up);
                    const float len = glm::length(axis);
                    if (len > 1e-4f)
                    {
                        axis /= len;
                        const float target = lp.attractionUp > 0.0f ? declination : glm::pi<float>() - declination;
                        const float angle = std::min(std::abs(lp.attractionUp) * 2.0f / float(n), 1.0f) * target;
                        frame = rotateFrame(frame, axis, lp.attractionUp > 0.0f ? angle : -angle);
                    }
                }
                frame = orthonormalise(frame);
                stem.segments.push_back(frame);
                stem.points.push_back(stem.points.back() + frame.z * segLength);
            }
            stem.radii.resize(stem.points.size());
            for (std::size_t i = 0; i < stem.points.size(); ++i)
            {
                const float t = float(i) / float(n);
                stem.radii[i] = stem.radiusAt(t) * (stem.level == 0 ? flareAt(flare, t) : 1.0f);
            }
        }

        /// Build the stems, parents before children (breadth first).
        std::vector<Stem> buildStems(const PresetParams& p, float height, std::uint32_t seed,
                                     const ProgressCallback& progress)
        {
            Random rnd(mixSeed(seed, 0x5e3d));
            std::vector<Stem> stems;
            const float minRadius = 0.0008f * height;

            for (int k = 0; k < p.trunks; ++k)
            {
                const LevelParams& tp = p.level[0];
                Stem trunk;
                trunk.level = 0;
                trunk.length = height * (tp.length + rnd.spread(tp.lengthV));
                trunk.radius = trunk.length * p.ratio;
                trunk.taper = tp.taper;
                Frame frame;
                glm::vec3 base(0.0f);
                if (p.trunks > 1)
                {
                    // Several stems from the ground, spread around by the golden angle.
                    const float azimuth = glm::radians(float(k) * 137.5f + rnd.spread(20.0f));
                    const float lean = glm::radians(rnd.range(p.trunkLeanMin, p.trunkLeanMax));
                    frame = rotateFrame(frame, frame.z, azimuth);
                    frame = rotateFrame(frame, frame.x, lean);
                    glm::vec3 out(frame.z.x, 0.0f, frame.z.z);
                    if (glm::length(out) > 1e-6f)
                        base = glm::normalize(out) * (p.trunkBaseSpread * height * std::sqrt(rnd.unit()));
                    // Lift a leaning stem so that its tilted base ring stays above ground.
                    base.y = trunk.radius * flareAt(p.flare, 0.0f) * std::sin(lean);
                }
                growStem(trunk, base, frame, tp, p.flare, rnd);
                stems.push_back(std::move(trunk));
            }
            const float trunkLength = height;

            for (std::size_t s = 0; s < stems.size(); ++s)
            {
                if ((s & 63) == 0)
                    report(progress, "generate stems", std::min(0.99f, float(s) / float(stems.size() + 1)));
                const int childLevel = stems[s].level + 1;
                if (childLevel >= p.levels)
                    continue;
                const LevelParams& cp = p.level[childLevel];
                const Stem parent = stems[s]; // copy: `stems` grows below

                // W&P: the trunk carries nBranches; deeper stems carry
                // nBranches * (0.2 + 0.8 * (length / parentLength) / lengthMax).
                float count;
                if (parent.level == 0)
                    count = float(cp.branches) * std::min(1.0f, parent.length / trunkLength);
                else
                {
                    const LevelParams& own = p.level[parent.level];
                    const float lengthMax = own.length + own.lengthV;
                    count = float(cp.branches) *
                            (0.2f + 0.8f * (parent.length / stems[parent.parent].length) / lengthMax);
                }
                const int n = int(std::floor(count + rnd.unit()));
                const float start = parent.level == 0 ? p.baseSize : cp.start;
                const float baseLength = start * parent.length;
                float rotation = rnd.range(0.0f, 360.0f);
                for (int j = 0; j < n; ++j)
                {
                    const float t = std::clamp(start + (1.0f - start) * (float(j) + 0.5f + rnd.spread(0.35f)) / float(n),
                                               start, 0.97f);
                    const float offset = t * parent.length;
                    const float ratio = (parent.length - offset) / std::max(1e-6f, parent.length - baseLength);

                    // W&P child length.
                    const float lengthMax = cp.length + rnd.spread(cp.lengthV);
                    float length = parent.level == 0 ? parent.length * lengthMax * shapeRatio(p.shape, ratio)
                                                     : lengthMax * (parent.length - 0.6f * offset);
                    // W&P down angle: a negative variation makes it depend on the position.
                    const float down = cp.downAngleV >= 0.0f
                                           ? cp.downAngle + rnd.spread(cp.downAngleV)
                                           : cp.downAngle + cp.downAngleV * (1.0f - 2.0f * shapeRatio(Conical, ratio));
                    // W&P rotate: phyllotaxis about the parent, or alternating sides.
                    if (cp.rotate >= 0.0f)
                        rotation += cp.rotate + rnd.spread(cp.rotateV);
                    else
                        rotation = -cp.rotate + (j % 2 ? 180.0f : 0.0f) + rnd.spread(cp.rotateV);
                    if (length < 0.002f * height)
                        continue;

                    Stem child;
                    child.level = childLevel;
                    child.parent = int(s);
                    child.offset = offset;
                    child.length = length;
                    child.taper = cp.taper;
                    // W&P radius: parent * (length / parentLength)^RatioPower, never thicker
                    // than the parent where it grows.
                    child.radius = parent.radius * std::pow(length / parent.length, p.ratioPower);
                    child.radius = std::max(minRadius, std::min(child.radius, 0.9f * parent.radiusAt(t)));

                    Frame frame = parent.segments[parent.segmentAt(t)];
                    frame = rotateFrame(frame, frame.z, glm::radians(rotation));
                    frame = rotateFrame(frame, frame.x, glm::radians(down));
                    growStem(child, parent.pointAt(t), frame, cp, 0.0f, rnd);
                    stems.push_back(std::move(child));
                }
            }
            return stems;
        }

        void scaleStems(std::vector<Stem>& stems, float scale)
        {
            for (Stem& s : stems)
            {
                s.offset *= scale;
                s.length *= scale;
                s.radius *= scale;
                for (glm::vec3& q : s.points)
                    q *= scale;
                for (float& r : s.radii)
                    r *= scale;
            }
        }

        void buildSkeleton(std::vector<Stem>& stems, TreeModel& model)
        {
            for (Stem& s : stems)
            {
                s.firstNode = std::int32_t(model.skeleton.size());
                std::int32_t parentNode = -1;
                if (s.parent >= 0)
                {
                    const Stem& par = stems[std::size_t(s.parent)];
                    parentNode = par.firstNode + par.segmentAt(s.offset / par.length);
                }
                for (std::size_t i = 0; i < s.points.size(); ++i)
                {
                    SkeletonNode node;
                    node.position = s.points[i];
                    node.radius = s.radii[i];
                    node.parent = i == 0 ? parentNode : s.firstNode + std::int32_t(i) - 1;
                    model.skeleton.push_back(node);
                }
            }
        }

        /// Bark tubes (W&P: a stem is a generalised cylinder): a ring of `sides` + 1
        /// vertices (seam duplicated for UVs) per stem point, closed by a cone at the tip.
        /// u runs once around the stem, v = length / base circumference (square texels).
        void buildBark(const std::vector<Stem>& stems, const PresetParams& p, TreeModel& model,
                       const ProgressCallback& progress)
        {
            for (std::size_t si = 0; si < stems.size(); ++si)
            {
                if ((si & 255) == 0)
                    report(progress, "generate bark", float(si) / float(stems.size()));
                const Stem& s = stems[si];
                const int sides = p.level[std::size_t(s.level)].sides;
                const std::size_t rings = s.points.size() - 1; // the last point is the apex
                const float vScale = 1.0f / (2.0f * glm::pi<float>() * std::max(s.radius, 1e-6f));
                const float segLength = s.length / float(s.segments.size());
                const std::uint32_t base = std::uint32_t(model.barkVertices.size());
                for (std::size_t i = 0; i < rings; ++i)
                {
                    const Frame f = s.ringFrame(i);
                    const float r = std::max(s.radii[i], 0.05f * s.radius);
                    const float v = float(i) * segLength * vScale;
                    for (int k = 0; k <= sides; ++k)
                    {
                        const float a = 2.0f * glm::pi<float>() * float(k % sides) / float(sides);
                        const glm::vec3 dir = f.x * std::cos(a) + f.y * std::sin(a);
                        model.barkVertices.push_back({s.points[i] + dir * r, dir, {float(k) / float(sides), v}});
                    }
                }
                const std::uint32_t apex = std::uint32_t(model.barkVertices.size());
                const glm::vec3 tipDir = s.segments.back().z;
                for (int k = 0; k < sides; ++k)
                    model.barkVertices.push_back(
                        {s.points.back(), tipDir, {(float(k) + 0.5f) / float(sides), float(rings) * segLength * vScale}});

                const std::uint32_t stride = std::uint32_t(sides) + 1;
                for (std::size_t i = 0; i + 1 < rings; ++i)
                    for (int k = 0; k < sides; ++k)
                    {
                        const std::uint32_t a = base + std::uint32_t(i) * stride + std::uint32_t(k);
                        const std::uint32_t b = a + 1, c = a + stride, d = c + 1;
                        model.barkIndices.insert(model.barkIndices.end(), {a, b, d, a, d, c});
                    }
                const std::uint32_t last = base + std::uint32_t(rings - 1) * stride;
                for (int k = 0; k < sides; ++k)
                    model.barkIndices.insert(model.barkIndices.end(),
                                             {last + std::uint32_t(k), last + std::uint32_t(k) + 1, apex + std::uint32_t(k)});
            }
            model.barkTriangleMaterial.assign(model.barkIndices.size() / 3, 0u);
        }

        /// Split `total` leaves over stems in proportion to `weights` by rounding the
        /// cumulative sums (systematic sampling): the counts add up to `total` exactly, and
        /// when there are fewer leaves than stems they spread evenly over the stem order
        /// (which runs up the tree) instead of piling onto the heaviest stems.
        std::vector<std::uint32_t> distribute(std::uint32_t total, const std::vector<double>& weights)
        {
            double sum = 0.0;
            for (double w : weights)
                sum += w;
            std::vector<std::uint32_t> counts(weights.size(), 0);
            double cumulative = 0.0;
            std::uint64_t given = 0;
            for (std::size_t i = 0; i < weights.size(); ++i)
            {
                cumulative += sum > 0.0 ? weights[i] : 1.0;
                const double fraction = i + 1 == weights.size() ? 1.0
                                        : cumulative / (sum > 0.0 ? sum : double(weights.size()));
                const std::uint64_t upTo = std::min<std::uint64_t>(total, std::uint64_t(std::floor(double(total) * fraction + 0.5)));
                counts[i] = std::uint32_t(upTo - std::min(upTo, given));
                given = std::max(given, upTo);
            }
            return counts;
        }

        /// Leaves on the last stem level (W&P: leaves per stem weighted by
        /// ShapeRatio(4, offset / parentLength), times the stem length here), each a quad
        /// whose base sits on a short invisible twig around the stem (phyllotaxis 137.5°).
        void buildLeaves(const std::vector<Stem>& stems, const PresetParams& p, float height, std::uint32_t leafCount,
                         float aspect, std::uint32_t seed, TreeModel& model, const ProgressCallback& progress)
        {
            int leafLevel = 0;
            for (const Stem& s : stems)
                leafLevel = std::max(leafLevel, s.level);
            std::vector<std::size_t> bearing;
            std::vector<double> weights;
            for (std::size_t i = 0; i < stems.size(); ++i)
            {
                const Stem& s = stems[i];
                if (s.level != leafLevel)
                    continue;
                const float along = s.parent >= 0 ? s.offset / stems[std::size_t(s.parent)].length : 1.0f;
                bearing.push_back(i);
                weights.push_back(double(s.length) * double(shapeRatio(TaperedCylindrical, along)));
            }
            const std::vector<std::uint32_t> counts = distribute(leafCount, weights);

            // Leaf size rule (see TreeGenerator.h): total quad area = k * height^2, each
            // leaf at most a tenth of the height long (only binds near 100 leaves).
            const float leafArea = p.leafAreaFactor * height * height / float(leafCount);
            const float leafLength = std::min(std::sqrt(leafArea / aspect), 0.1f * height);
            const float halfWidth = 0.5f * aspect * leafLength;
            // Leaves fill a tube of radius `reach` around their stem whatever their size:
            // the invisible twig is as long as the leaf leaves room for (at least a quarter).
            const float reach = p.leafSpread * height;
            const float spread = std::max(reach - leafLength, 0.25f * reach);
            const glm::vec3 up(0.0f, 1.0f, 0.0f);

            model.leafVertices.reserve(std::size_t(leafCount) * 4);
            model.leafIndices.reserve(std::size_t(leafCount) * 6);
            model.leaves.reserve(leafCount);
            for (std::size_t b = 0; b < bearing.size(); ++b)
            {
                if ((b & 127) == 0)
                    report(progress, "generate leaves", float(b) / float(bearing.size()));
                const Stem& s = stems[bearing[b]];
                const std::uint32_t n = counts[b];
                Random rnd(mixSeed(seed ^ 0x1eafu, std::uint32_t(bearing[b])));
                float rotation = rnd.range(0.0f, 360.0f);
                for (std::uint32_t j = 0; j < n; ++j)
                {
                    const float t = std::clamp(
                        p.leafStart + (1.0f - p.leafStart) * (float(j) + 0.5f + rnd.spread(0.45f)) / float(n), 0.0f, 1.0f);
                    rotation += 137.5f + rnd.spread(25.0f);
                    const Frame f = s.segments[s.segmentAt(t)];
                    const float phi = glm::radians(rotation);
                    const glm::vec3 radial = f.x * std::cos(phi) + f.y * std::sin(phi);
                    // Two draws, in this order: operands of + are unsequenced, so they are named.
                    const float along = 0.5f * spread * rnd.spread(1.0f);
                    const float out = spread * std::sqrt(rnd.unit());
                    const glm::vec3 basePos = s.pointAt(t) + radial * out + f.z * along;

                    // Leaf axis: off the stem by the leaf down angle, bent up or down.
                    const float down = glm::radians(p.leafDownAngle + rnd.spread(p.leafDownAngleV));
                    glm::vec3 axis = f.z * std::cos(down) + radial * std::sin(down);
                    axis = glm::normalize(axis + up * p.leafBend);
                    // Face: towards the sky and outwards from the trunk, rolled at random.
                    glm::vec3 outward(basePos.x, 0.0f, basePos.z);
                    outward = glm::length(outward) > 1e-6f ? glm::normalize(outward) : radial;
                    glm::vec3 face = glm::normalize(up * p.leafFaceUp + outward * (1.0f - p.leafFaceUp));
                    face -= axis * glm::dot(face, axis);
                    if (glm::length(face) < 1e-3f)
                        face = glm::cross(axis, f.x);
                    face = glm::normalize(face);
                    face = rotateAbout(face, axis, glm::radians(rnd.spread(p.leafTwistV)));
                    const glm::vec3 across = glm::cross(axis, face);

                    const float sizeJitter = 1.0f + rnd.spread(0.15f);
                    const glm::vec3 w = across * (halfWidth * sizeJitter);
                    glm::vec3 base = basePos;
                    glm::vec3 tip = basePos + axis * (leafLength * sizeJitter);
                    // Leaves hanging into the ground are lifted onto it.
                    const float lowest = std::min({base.y - std::abs(w.y), tip.y - std::abs(w.y)});
                    if (lowest < 0.0f)
                    {
                        base.y -= lowest;
                        tip.y -= lowest;
                    }

                    Leaf leaf;
                    leaf.firstVertex = std::uint32_t(model.leafVertices.size());
                    leaf.vertexCount = 4;
                    leaf.firstIndex = std::uint32_t(model.leafIndices.size());
                    leaf.indexCount = 6;
                    leaf.material = 1;
                    // Petiole at the bottom of the texture (v = 1), tip at the top (v = 0);
                    // (across, axis, face) is right-handed, so the triangles face `face`.
                    model.leafVertices.push_back({base - w, face, {0.0f, 1.0f}});
                    model.leafVertices.push_back({base + w, face, {1.0f, 1.0f}});
                    model.leafVertices.push_back({tip + w, face, {1.0f, 0.0f}});
                    model.leafVertices.push_back({tip - w, face, {0.0f, 0.0f}});
                    const std::uint32_t v0 = leaf.firstVertex;
                    model.leafIndices.insert(model.leafIndices.end(), {v0, v0 + 1, v0 + 2, v0, v0 + 2, v0 + 3});
                    model.leaves.push_back(leaf);
                    model.updateLeafRecord(model.leaves.size() - 1);
                }
            }
        }
        /// GeneratorOptions::leafFold: each quad leaf (base - w, base + w, tip + w, tip - w, as
        /// buildLeaves makes them) becomes two quads sharing the midrib, each wing raised by
        /// `degrees` towards the face; u = 0.5 on the midrib. Same draws, so the same tree.
        void foldLeaves(float degrees, TreeModel& model)
        {
            const float c = std::cos(glm::radians(degrees)), s = std::sin(glm::radians(degrees));
            std::vector<Vertex> vertices;
            std::vector<std::uint32_t> indices;
            vertices.reserve(model.leafVertices.size() / 2 * 3);
            indices.reserve(model.leafIndices.size() * 2);
            for (std::size_t l = 0; l < model.leaves.size(); ++l)
            {
                Leaf& leaf = model.leaves[l];
                const Vertex* q = &model.leafVertices[leaf.firstVertex];
                const glm::vec3 face = q[0].normal;
                const glm::vec3 w = 0.5f * (q[1].position - q[0].position);
                const glm::vec3 base = 0.5f * (q[0].position + q[1].position), tip = 0.5f * (q[2].position + q[3].position);
                const glm::vec3 lift = face * (glm::length(w) * s);
                const glm::vec3 left = -w * c + lift, right = w * c + lift;
                const auto facing = [&](const glm::vec3& n) { return glm::normalize(glm::dot(n, face) < 0.0f ? -n : n); };
                const glm::vec3 leftNormal = facing(glm::cross(tip - base, left));
                const glm::vec3 rightNormal = facing(glm::cross(tip - base, right));
                const std::uint32_t v0 = std::uint32_t(vertices.size());
                vertices.push_back({base + left, leftNormal, {0.0f, 1.0f}});
                vertices.push_back({base, face, {0.5f, 1.0f}});
                vertices.push_back({base + right, rightNormal, {1.0f, 1.0f}});
                vertices.push_back({tip + left, leftNormal, {0.0f, 0.0f}});
                vertices.push_back({tip, face, {0.5f, 0.0f}});
                vertices.push_back({tip + right, rightNormal, {1.0f, 0.0f}});
                leaf.firstVertex = v0;
                leaf.vertexCount = 6;
                leaf.firstIndex = std::uint32_t(indices.size());
                leaf.indexCount = 12;
                for (std::uint32_t k : {0u, 1u, 4u, 0u, 4u, 3u, 1u, 2u, 5u, 1u, 5u, 4u})
                    indices.push_back(v0 + k);
            }
            model.leafVertices = std::move(vertices);
            model.leafIndices = std::move(indices);
            for (std::size_t l = 0; l < model.leaves.size(); ++l)
                model.updateLeafRecord(l);
        }

        /// GeneratorOptions::leafImages: a 2 x 2 atlas of leaf images (this preset's first) and
        /// each leaf's UVs moved into one cell. Images of other presets are stretched to this
        /// preset's leaf aspect, as atlas leaves on a shared quad shape are.
        TextureImage buildLeafAtlas(TreePreset preset, int size, std::uint32_t images, std::uint32_t seed,
                                    TreeModel& model)
        {
            TextureImage atlas;
            atlas.width = atlas.height = size;
            atlas.rgba.assign(std::size_t(size) * std::size_t(size) * 4, 0);
            const int cell = size / 2;
            std::vector<TreePreset> order{preset};
            for (TreePreset p : {TreePreset::Oak, TreePreset::Birch, TreePreset::Shrub, TreePreset::Conifer})
                if (p != preset)
                    order.push_back(p);
            for (std::uint32_t i = 0; i < images; ++i)
            {
                const TextureImage image = drawLeafTexture(order[i], cell);
                const int ox = int(i % 2) * cell, oy = int(i / 2) * cell;
                for (int y = 0; y < cell; ++y)
                    std::copy_n(&image.rgba[std::size_t(y) * std::size_t(cell) * 4], std::size_t(cell) * 4,
                                &atlas.rgba[(std::size_t(oy + y) * std::size_t(size) + std::size_t(ox)) * 4]);
            }
            Random rnd(mixSeed(seed, 0xa71a5u));
            for (std::size_t l = 0; l < model.leaves.size(); ++l)
            {
                const std::uint32_t i = std::min(std::uint32_t(rnd.unit() * float(images)), images - 1);
                const glm::vec2 origin(float(i % 2), float(i / 2));
                const Leaf& leaf = model.leaves[l];
                for (std::uint32_t v = leaf.firstVertex; v < leaf.firstVertex + leaf.vertexCount; ++v)
                    model.leafVertices[v].uv = 0.5f * (origin + model.leafVertices[v].uv);
                model.updateLeafRecord(l);
            }
            return atlas;
        }

        /// GeneratorOptions::leafMaterials: copies of `leaf` with their own tint and cutoff,
        /// leaves dealt to them in turn.
        void splitLeafMaterials(const Material& leaf, const glm::vec3& meanColour, std::uint32_t count,
                                TreeModel& model)
        {
            static const glm::vec3 kTints[] = {{1.0f, 1.0f, 1.0f},   {1.0f, 0.72f, 0.42f}, {0.78f, 1.0f, 0.8f},
                                               {1.0f, 0.5f, 0.3f},   {0.92f, 0.95f, 0.55f}, {0.6f, 0.8f, 0.6f},
                                               {1.0f, 0.85f, 0.25f}, {0.7f, 0.62f, 0.5f}};
            const std::uint32_t first = std::uint32_t(model.materials.size());
            for (std::uint32_t m = 0; m < count; ++m)
            {
                Material material = leaf;
                const glm::vec3 tint = kTints[m % 8] * (m < 8 ? 1.0f : 0.8f);
                material.name = m == 0 ? leaf.name : leaf.name + " " + std::to_string(m + 1);
                material.baseColour = glm::vec4(tint, 1.0f);
                material.backColour = glm::clamp(meanColour * tint * glm::vec3(1.9f, 1.5f, 0.8f), glm::vec3(0.0f),
                                                 glm::vec3(1.0f));
                material.alphaCutoff = m == 0 ? 0.5f : 0.3f + 0.05f * float((m * 3) % 9);
                model.materials.push_back(material);
            }
            for (std::size_t l = 0; l < model.leaves.size(); ++l)
                model.leaves[l].material = first + std::uint32_t(l % count);
        }
    }

    std::uint32_t presetDefaultLeafCount(TreePreset preset) { return presetParams(preset).leaves; }
    float presetDefaultHeight(TreePreset preset) { return presetParams(preset).height; }

    Result<TreeModel> generateTree(const GeneratorOptions& options, const ProgressCallback& progress)
    {
        if (options.preset != TreePreset::Oak && options.preset != TreePreset::Conifer &&
            options.preset != TreePreset::Birch && options.preset != TreePreset::Shrub)
            return fail("", "option --preset", "unknown preset");
        const PresetParams p = presetParams(options.preset);
        const std::uint32_t leafCount = options.leafCount == 0 ? p.leaves : options.leafCount;
        if (leafCount < kMinLeaves || leafCount > kMaxLeaves)
            return fail("", "option --leaves",
                        "leaf count " + std::to_string(leafCount) + " is outside " + std::to_string(kMinLeaves) +
                            ".." + std::to_string(kMaxLeaves));
        const float height = options.height == 0.0f ? p.height : options.height;
        if (!std::isfinite(height) || height < 0.1f || height > 1000.0f)
            return fail("", "option --height", "height " + std::to_string(options.height) + " m is outside 0.1..1000 m");
        const int ts = options.textureSize;
        if (ts < 16 || ts > 4096 || (ts & (ts - 1)) != 0)
            return fail("", "option --texture-size",
                        "texture size " + std::to_string(ts) + " is not a power of two in 16..4096");

        if (options.leafImages < 1 || options.leafImages > 4)
            return fail("", "option --leaf-images",
                        std::to_string(options.leafImages) + " leaf images; 1..4 are drawn");
        if (!(options.leafFold >= 0.0f && options.leafFold <= 80.0f))
            return fail("", "option --leaf-fold", "leaf fold " + std::to_string(options.leafFold) +
                                                      " degrees is outside 0..80");
        if (options.leafMaterials < 1 || options.leafMaterials > 16)
            return fail("", "option --leaf-materials",
                        std::to_string(options.leafMaterials) + " leaf materials; 1..16 are made");

        TreeModel model;
        model.name = std::string(presetName(options.preset)) + " seed " + std::to_string(options.seed);

        // Stems at the nominal height, then scaled so the top of the stems is the height.
        std::vector<Stem> stems = buildStems(p, height, options.seed, progress);
        float top = 0.0f;
        for (const Stem& s : stems)
            for (const glm::vec3& q : s.points)
                top = std::max(top, q.y);
        if (top > 0.0f)
            scaleStems(stems, height / top);
        report(progress, "generate stems", 1.0f);

        buildSkeleton(stems, model);
        buildBark(stems, p, model, progress);
        report(progress, "generate bark", 1.0f);

        const float aspect = leafAspect(options.preset);
        buildLeaves(stems, p, height, leafCount, aspect, options.seed, model, progress);
        if (options.leafFold > 0.0f)
            foldLeaves(options.leafFold, model);
        report(progress, "generate leaves", 1.0f);

        report(progress, "draw textures", 0.0f);
        const std::string name = presetName(options.preset);
        TextureImage bark = drawBarkTexture(options.preset, std::max(16, ts / 2), std::max(16, ts / 2));
        bark.name = name + "_bark.png";
        TextureImage leafTexture = options.leafImages > 1
                                       ? buildLeafAtlas(options.preset, ts, options.leafImages, options.seed, model)
                                       : drawLeafTexture(options.preset, ts);
        leafTexture.name = name + (options.leafImages > 1 ? "_leaf_atlas.png" : "_leaf.png");

        Material barkMaterial;
        barkMaterial.name = "Bark";
        barkMaterial.texture = 0;
        Material leafMaterial;
        leafMaterial.name = "Leaves";
        leafMaterial.texture = 1;
        leafMaterial.isLeaf = true;
        leafMaterial.doubleSided = true;
        leafMaterial.alphaCutoff = 0.5f;
        // Back side: light shining through a leaf is lighter and yellower (linear RGB).
        const glm::vec3 mean = leafMeanColour(leafTexture);
        leafMaterial.backColour = glm::clamp(mean * glm::vec3(1.9f, 1.5f, 0.8f), glm::vec3(0.0f), glm::vec3(1.0f));

        model.textures.push_back(std::move(bark));
        model.textures.push_back(std::move(leafTexture));
        model.materials.push_back(barkMaterial);
        if (options.leafMaterials > 1)
            splitLeafMaterials(leafMaterial, mean, options.leafMaterials, model);
        else
            model.materials.push_back(leafMaterial);
        model.updateBounds();
        report(progress, "draw textures", 1.0f);
        return model;
    }
}
