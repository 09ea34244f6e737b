// VectorQuantiser: GLA texture compression of the 4x4 billboards in CIELab (Linz et al. 2006, §4.1)
// (contract in VectorQuantiser.h).
//
// The nearest-codeword search is exact (nearest by the float squared distance, ties to the lowest
// index) but prunes with three bounds: a per-vector lower bound of the distance to every codeword
// but its own, carried across iterations by subtracting how far the codewords moved (Hamerly 2010);
// a kd-tree over the codewords' features (coordinates on the 3 principal axes and the norm of the
// rest), whose distances bound the true ones from below; and partial distances abandoned once they
// pass the second-nearest. Each vector's search reads only shared data, so results do not depend
// on the thread count.
#include "TreeLod/VectorQuantiser.h"

#include "TreeLod/Colour.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>

#if defined(__SSE2__) || defined(_M_X64)
#include <emmintrin.h>
#define TREELOD_VQ_SSE 1
#endif

namespace TreeLod
{
    namespace
    {
        constexpr float FLOAT_INF = std::numeric_limits<float>::infinity();
        constexpr double DOUBLE_INF = std::numeric_limits<double>::infinity();
        constexpr std::uint32_t NONE = std::numeric_limits<std::uint32_t>::max();
        constexpr int COLOUR_DIM = 3 * BILLBOARD_TEXELS;

        // ---- Distances ------------------------------------------------------------------------

        inline float total(const float (&acc)[8])
        {
            return ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]));
        }

#ifdef TREELOD_VQ_SSE
        /// total() of the lanes lo = acc[0..3], hi = acc[4..7], in the same order.
        inline float total(__m128 lo, __m128 hi)
        {
            const __m128 pairs = _mm_add_ps(_mm_shuffle_ps(lo, hi, _MM_SHUFFLE(2, 0, 2, 0)),
                                            _mm_shuffle_ps(lo, hi, _MM_SHUFFLE(3, 1, 3, 1)));
            const __m128 quads = _mm_add_ps(_mm_shuffle_ps(pairs, pairs, _MM_SHUFFLE(2, 0, 2, 0)),
                                            _mm_shuffle_ps(pairs, pairs, _MM_SHUFFLE(3, 1, 3, 1)));
            return _mm_cvtss_f32(_mm_add_ss(quads, _mm_shuffle_ps(quads, quads, _MM_SHUFFLE(1, 1, 1, 1))));
        }
#endif

        /// Squared L2 distance: component c is added to lane c mod 8, the 8 lanes in a fixed order
        /// (the SSE path computes the same bits). Once the running total exceeds `bound` that total
        /// is returned early: it never decreases, so an early return is > bound and <= the distance.
        inline float squaredDistance(const float* a, const float* b, int dim, float bound)
        {
            float acc[8] = {};
            int i = 0;
#ifdef TREELOD_VQ_SSE
            __m128 lo = _mm_setzero_ps(), hi = _mm_setzero_ps();
            for (; i + 16 <= dim; i += 16)
            {
                const __m128 d0 = _mm_sub_ps(_mm_loadu_ps(a + i), _mm_loadu_ps(b + i));
                const __m128 d1 = _mm_sub_ps(_mm_loadu_ps(a + i + 4), _mm_loadu_ps(b + i + 4));
                const __m128 d2 = _mm_sub_ps(_mm_loadu_ps(a + i + 8), _mm_loadu_ps(b + i + 8));
                const __m128 d3 = _mm_sub_ps(_mm_loadu_ps(a + i + 12), _mm_loadu_ps(b + i + 12));
                lo = _mm_add_ps(_mm_add_ps(lo, _mm_mul_ps(d0, d0)), _mm_mul_ps(d2, d2));
                hi = _mm_add_ps(_mm_add_ps(hi, _mm_mul_ps(d1, d1)), _mm_mul_ps(d3, d3));
                if (i + 16 < dim)
                {
                    const float s = total(lo, hi);
                    if (s > bound)
                        return s;
                }
            }
            if (i == dim)
                return total(lo, hi);
            _mm_storeu_ps(acc, lo);
            _mm_storeu_ps(acc + 4, hi);
#else
            for (; i + 16 <= dim; i += 16)
            {
                for (int k = 0; k < 8; ++k)
                {
                    const float d = a[i + k] - b[i + k];
                    acc[k] += d * d;
                }
                for (int k = 0; k < 8; ++k)
                {
                    const float d = a[i + 8 + k] - b[i + 8 + k];
                    acc[k] += d * d;
                }
                if (i + 16 < dim)
                {
                    const float s = total(acc);
                    if (s > bound)
                        return s;
                }
            }
#endif
            for (; i < dim; ++i)
            {
                const float d = a[i] - b[i];
                acc[i & 7] += d * d;
            }
            return total(acc);
        }

        double squaredDistanceDouble(const float* a, const float* b, int dim)
        {
            double s = 0.0;
            for (int i = 0; i < dim; ++i)
            {
                const double d = double(a[i]) - double(b[i]);
                s += d * d;
            }
            return s;
        }

        // ---- Distinct vectors and the initial draw --------------------------------------------

        std::uint64_t hashVector(const float* v, int dim)
        {
            std::uint64_t h = 0x9E3779B97F4A7C15ull;
            for (int i = 0; i < dim; ++i)
            {
                const float c = v[i] == 0.0f ? 0.0f : v[i]; // -0 == +0, so both hash alike
                std::uint32_t bits;
                std::memcpy(&bits, &c, sizeof bits);
                h = (h ^ bits) * 0xFF51AFD7ED558CCDull;
                h ^= h >> 29;
            }
            h ^= h >> 33;
            h *= 0xC4CEB9FE1A85EC53ull;
            h ^= h >> 33;
            return h;
        }

        /// The first occurrence of every distinct vector (exact float equality), in index order.
        std::vector<std::uint32_t> distinctVectors(const float* data, std::size_t count, int dim)
        {
            std::vector<std::uint64_t> hashes(count);
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 4096),
                              [&](const tbb::blocked_range<std::size_t>& r) {
                                  for (std::size_t i = r.begin(); i < r.end(); ++i)
                                      hashes[i] = hashVector(data + i * dim, dim);
                              });
            std::size_t capacity = 16;
            while (capacity < 2 * count)
                capacity *= 2;
            std::vector<std::uint32_t> table(capacity, NONE); // open addressing, linear probing
            std::vector<std::uint32_t> firsts;
            for (std::size_t i = 0; i < count; ++i)
            {
                const float* v = data + i * dim;
                std::size_t slot = std::size_t(hashes[i]) & (capacity - 1);
                for (;; slot = (slot + 1) & (capacity - 1))
                {
                    const std::uint32_t j = table[slot];
                    if (j == NONE)
                    {
                        table[slot] = std::uint32_t(i);
                        firsts.push_back(std::uint32_t(i));
                        break;
                    }
                    if (hashes[j] == hashes[i] && std::equal(v, v + dim, data + std::size_t(j) * dim))
                        break;
                }
            }
            return firsts;
        }

        /// Uniform integer in [0, n), n >= 1, from raw mt19937_64 output (rejection keeps it
        /// unbiased); written out because std distributions differ between standard libraries.
        std::uint64_t drawBelow(std::mt19937_64& rng, std::uint64_t n)
        {
            const std::uint64_t max = std::numeric_limits<std::uint64_t>::max();
            const std::uint64_t limit = max - max % n; // a multiple of n
            std::uint64_t r = rng();
            while (r >= limit)
                r = rng();
            return r % n;
        }

        // ---- Principal axes -------------------------------------------------------------------

        constexpr std::size_t AXES = 3;

        /// The mean and min(AXES, dim) orthonormal principal axes (row-major) of up to 32768 evenly
        /// strided vectors, by power iteration with Gram-Schmidt. Any orthonormal axes keep the
        /// search's bounds valid; principal ones only make them tighter.
        void principalAxes(const float* data, std::size_t count, std::size_t d, std::vector<double>& mean,
                           std::vector<double>& axes)
        {
            const std::size_t stride = std::max<std::size_t>(1, count / 32768);
            std::vector<double> cov(d * d, 0.0), x(d);
            mean.assign(d, 0.0);
            std::size_t samples = 0;
            for (std::size_t i = 0; i < count; i += stride, ++samples)
                for (std::size_t c = 0; c < d; ++c)
                    mean[c] += data[i * d + c];
            for (double& m : mean)
                m /= double(samples);
            for (std::size_t i = 0; i < count; i += stride)
            {
                for (std::size_t c = 0; c < d; ++c)
                    x[c] = data[i * d + c] - mean[c];
                for (std::size_t r = 0; r < d; ++r)
                    for (std::size_t c = r; c < d; ++c)
                        cov[r * d + c] += x[r] * x[c];
            }
            for (std::size_t r = 0; r < d; ++r)
                for (std::size_t c = 0; c < r; ++c)
                    cov[r * d + c] = cov[c * d + r];

            const std::size_t axisCount = std::min(AXES, d);
            axes.assign(axisCount * d, 0.0);
            std::vector<double> v(d), next(d);
            // Unit v orthogonal to the axes before `a`; false when v has nothing left.
            const auto orthonormalise = [&](std::size_t a, std::vector<double>& w) {
                for (std::size_t b = 0; b < a; ++b)
                {
                    double dot = 0.0;
                    for (std::size_t c = 0; c < d; ++c)
                        dot += w[c] * axes[b * d + c];
                    for (std::size_t c = 0; c < d; ++c)
                        w[c] -= dot * axes[b * d + c];
                }
                double norm = 0.0;
                for (double wc : w)
                    norm += wc * wc;
                norm = std::sqrt(norm);
                if (!(norm > 1e-12) || !std::isfinite(norm))
                    return false;
                for (double& wc : w)
                    wc /= norm;
                return true;
            };
            for (std::size_t a = 0; a < axisCount; ++a)
            {
                // A fixed start that no axis is likely orthogonal to; a basis vector if it is.
                for (std::size_t c = 0; c < d; ++c)
                    v[c] = 1.0 + 0.5 * std::cos(double((a + 1) * (c + 1)));
                for (std::size_t e = 0; !orthonormalise(a, v); ++e)
                {
                    std::fill(v.begin(), v.end(), 0.0);
                    v[e] = 1.0;
                }
                for (int iteration = 0; iteration < 64; ++iteration)
                {
                    for (std::size_t r = 0; r < d; ++r)
                    {
                        double s = 0.0;
                        for (std::size_t c = 0; c < d; ++c)
                            s += cov[r * d + c] * v[c];
                        next[r] = s;
                    }
                    if (!orthonormalise(a, next))
                        break; // v is in the covariance's null space: keep it
                    v.swap(next);
                }
                std::copy(v.begin(), v.end(), &axes[a * d]);
            }
        }

        // ---- Nearest-codeword search ----------------------------------------------------------

        /// Per vector: its coordinates on the principal axes (about the mean) and the norm of the
        /// rest. The squared Euclidean distance of two vectors' features is a lower bound of their
        /// squared distance.
        constexpr std::size_t FEATURES = AXES + 1;
        using Features = std::array<double, FEATURES>;

        double featureDistance(const Features& a, const Features& b)
        {
            double s = 0.0;
            for (std::size_t f = 0; f < FEATURES; ++f)
                s += (a[f] - b[f]) * (a[f] - b[f]);
            return s;
        }

        /// A kd-tree of the codewords' features: a node's subtree is a range of `order`, its box
        /// bounds their features, and the squared distance to the box bounds their distances.
        class CodewordTree
        {
        public:
            static constexpr std::uint32_t LEAF_SIZE = 8;

            struct Node
            {
                Features lo, hi;
                std::uint32_t begin = 0, end = 0;
                std::uint32_t left = NONE, right = NONE; ///< children; NONE for a leaf
            };

            CodewordTree(const std::vector<Features>& codewordFeatures)
            {
                const std::uint32_t k = std::uint32_t(codewordFeatures.size());
                order.resize(k);
                std::iota(order.begin(), order.end(), 0u);
                build(codewordFeatures, 0, k);
                features.resize(k);
                for (std::uint32_t s = 0; s < k; ++s)
                    features[s] = codewordFeatures[order[s]];
            }

            static double boxDistance(const Node& node, const Features& x)
            {
                double s = 0.0;
                for (std::size_t f = 0; f < FEATURES; ++f)
                {
                    const double out = std::max(0.0, std::max(node.lo[f] - x[f], x[f] - node.hi[f]));
                    s += out * out;
                }
                return s;
            }

            std::vector<Node> nodes;          ///< nodes[0] is the root
            std::vector<std::uint32_t> order; ///< codeword indices, each leaf's contiguous
            std::vector<Features> features;   ///< of order[s]

        private:
            /// Median split on the widest feature; the (feature, index) order is total, so the tree is
            /// the same with any standard library.
            std::uint32_t build(const std::vector<Features>& all, std::uint32_t begin, std::uint32_t end)
            {
                const std::uint32_t id = std::uint32_t(nodes.size());
                nodes.emplace_back();
                Node node;
                node.begin = begin;
                node.end = end;
                node.lo.fill(DOUBLE_INF);
                node.hi.fill(-DOUBLE_INF);
                for (std::uint32_t s = begin; s < end; ++s)
                    for (std::size_t f = 0; f < FEATURES; ++f)
                    {
                        node.lo[f] = std::min(node.lo[f], all[order[s]][f]);
                        node.hi[f] = std::max(node.hi[f], all[order[s]][f]);
                    }
                if (end - begin > LEAF_SIZE)
                {
                    std::size_t split = 0;
                    for (std::size_t f = 1; f < FEATURES; ++f)
                        if (node.hi[f] - node.lo[f] > node.hi[split] - node.lo[split])
                            split = f;
                    const std::uint32_t mid = begin + (end - begin) / 2;
                    std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                                     [&](std::uint32_t a, std::uint32_t b) {
                                         const double fa = all[a][split], fb = all[b][split];
                                         return fa < fb || (fa == fb && a < b);
                                     });
                    node.left = build(all, begin, mid);
                    node.right = build(all, mid, end);
                }
                nodes[id] = node;
                return id;
            }
        };

        class NearestCodeword
        {
        public:
            std::vector<std::uint32_t> assignment; ///< per vector
            std::vector<float> distance;           ///< per vector, squared, to its codeword

            NearestCodeword(const float* data, std::size_t count, int dim)
                : assignment(count, NONE), distance(count, 0.0f), mData(data), mCount(count), mDim(dim),
                  mFeatures(count), mLower(count, 0.0),
                  // A float squared distance is within (dim + 2) float ulps (relative) of the exact
                  // one; four times that keeps every bound conservative.
                  mSlack(std::max(1e-6, 4.0 * (dim + 4) * double(std::numeric_limits<float>::epsilon())))
            {
                principalAxes(data, count, std::size_t(dim), mMean, mAxes);
                tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 4096),
                                  [&](const tbb::blocked_range<std::size_t>& r) {
                                      std::vector<double> rest(static_cast<std::size_t>(mDim));
                                      for (std::size_t i = r.begin(); i < r.end(); ++i)
                                          mFeatures[i] = features(data + i * std::size_t(dim), rest);
                                  });
                // Features carry double rounding of about 1e-14 |x - mean|: an absolute margin for them.
                double largest = 0.0;
                for (const Features& f : mFeatures)
                {
                    double normSquared = 0.0;
                    for (double v : f)
                        normSquared += v * v;
                    largest = std::max(largest, normSquared);
                }
                mFeatureSlack = 1e-11 * largest;
            }

            /// Assign every vector to its nearest codeword of `codebook`. `previous` is the codebook
            /// of the last call (empty on the first): the per-vector bounds then carry over.
            void assign(const std::vector<float>& codebook, const std::vector<float>& previous)
            {
                const std::size_t d = std::size_t(mDim);
                const std::uint32_t k = std::uint32_t(codebook.size() / d);
                const bool carry = previous.size() == codebook.size();

                // Hamerly's bound update: every other codeword came at most this much closer.
                double maxMove = 0.0, secondMove = 0.0;
                std::uint32_t maxMover = NONE;
                if (carry)
                    for (std::uint32_t j = 0; j < k; ++j)
                    {
                        const double m = std::sqrt(squaredDistanceDouble(&codebook[j * d], &previous[j * d], mDim));
                        if (m > maxMove)
                        {
                            secondMove = maxMove;
                            maxMove = m;
                            maxMover = j;
                        }
                        else if (m > secondMove)
                            secondMove = m;
                    }

                std::vector<Features> codewordFeatures(k);
                std::vector<double> rest(d);
                for (std::uint32_t j = 0; j < k; ++j)
                    codewordFeatures[j] = features(&codebook[j * d], rest);
                const CodewordTree tree(codewordFeatures);

                tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mCount, 1024),
                                  [&](const tbb::blocked_range<std::size_t>& r) {
                                      for (std::size_t i = r.begin(); i < r.end(); ++i)
                                          search(i, codebook.data(), tree,
                                                 carry ? (assignment[i] == maxMover ? secondMove : maxMove) : -1.0);
                                  });
            }

            double meanSquaredError() const
            {
                double sum = 0.0;
                for (float v : distance)
                    sum += v;
                return sum / double(mCount);
            }

        private:
            Features features(const float* v, std::vector<double>& rest) const
            {
                const std::size_t d = std::size_t(mDim), axisCount = mAxes.size() / d;
                Features out{};
                for (std::size_t c = 0; c < d; ++c)
                    rest[c] = v[c] - mMean[c];
                for (std::size_t a = 0; a < axisCount; ++a)
                {
                    const double* axis = &mAxes[a * d];
                    double p = 0.0;
                    for (std::size_t c = 0; c < d; ++c)
                        p += axis[c] * rest[c];
                    out[a] = p;
                    for (std::size_t c = 0; c < d; ++c)
                        rest[c] -= p * axis[c];
                }
                double norm = 0.0;
                for (double r : rest)
                    norm += r * r;
                out[AXES] = std::sqrt(norm);
                return out;
            }

            /// Nearest codeword of vector i (the previous one kept when the carried bound allows;
            /// `otherMove` < 0: no previous one).
            void search(std::size_t i, const float* codebook, const CodewordTree& tree, double otherMove)
            {
                const std::size_t d = std::size_t(mDim);
                const float* x = mData + i * d;
                float best = FLOAT_INF, second = FLOAT_INF; // second: lower bound for all others
                std::uint32_t bestIndex = NONE;
                if (otherMove >= 0.0)
                {
                    // Start from the previous codeword; keep it without a search when no other
                    // codeword can have come close enough (Hamerly 2010).
                    bestIndex = assignment[i];
                    best = squaredDistance(x, codebook + bestIndex * d, mDim, FLOAT_INF);
                    mLower[i] -= otherMove * (1.0 + mSlack);
                    if (std::sqrt(double(best)) * (1.0 + mSlack) < mLower[i])
                    {
                        distance[i] = best;
                        return;
                    }
                }
                const std::uint32_t skip = bestIndex;
                const Features& fx = mFeatures[i];
                // Depth-first, nearer child first; a node or codeword whose feature distance exceeds
                // `second` cannot hold the nearest or the second nearest.
                std::array<std::pair<std::uint32_t, double>, 128> stack;
                std::size_t top = 0;
                stack[top++] = {0u, CodewordTree::boxDistance(tree.nodes[0], fx)};
                while (top > 0)
                {
                    const auto [n, boxDistance] = stack[--top];
                    const double limit = double(second) * (1.0 + mSlack) + mFeatureSlack;
                    if (boxDistance > limit)
                        continue;
                    const CodewordTree::Node& node = tree.nodes[n];
                    if (node.left != NONE)
                    {
                        const double left = CodewordTree::boxDistance(tree.nodes[node.left], fx);
                        const double right = CodewordTree::boxDistance(tree.nodes[node.right], fx);
                        const bool leftFirst = left <= right;
                        stack[top++] = leftFirst ? std::make_pair(node.right, right) : std::make_pair(node.left, left);
                        stack[top++] = leftFirst ? std::make_pair(node.left, left) : std::make_pair(node.right, right);
                        continue;
                    }
                    for (std::uint32_t s = node.begin; s < node.end; ++s)
                    {
                        const std::uint32_t j = tree.order[s];
                        if (j == skip ||
                            featureDistance(fx, tree.features[s]) > double(second) * (1.0 + mSlack) + mFeatureSlack)
                            continue;
                        const float dj = squaredDistance(x, codebook + j * d, mDim, second);
                        if (dj < best || (dj == best && j < bestIndex))
                        {
                            second = best;
                            best = dj;
                            bestIndex = j;
                        }
                        else if (dj < second)
                            second = dj;
                    }
                }
                assignment[i] = bestIndex;
                distance[i] = best;
                mLower[i] = second == FLOAT_INF ? DOUBLE_INF : std::sqrt(double(second)) * (1.0 - mSlack);
            }

            const float* mData;
            std::size_t mCount;
            int mDim;
            std::vector<double> mMean, mAxes;
            std::vector<Features> mFeatures; ///< per vector
            std::vector<double> mLower; ///< per vector, lower bound of the distance to every other codeword
            double mSlack;              ///< relative margin on float distances
            double mFeatureSlack = 0.0; ///< absolute margin on feature distances
        };

        /// Vectors grouped by codeword, each group in index order (a counting sort).
        struct Clusters
        {
            std::vector<std::size_t> start; ///< K + 1
            std::vector<std::uint32_t> members;

            Clusters(const std::vector<std::uint32_t>& assignment, std::uint32_t k)
                : start(k + 1, 0), members(assignment.size())
            {
                for (std::uint32_t a : assignment)
                    ++start[a + 1];
                for (std::uint32_t j = 0; j < k; ++j)
                    start[j + 1] += start[j];
                std::vector<std::size_t> next(start.begin(), start.end() - 1);
                for (std::size_t i = 0; i < assignment.size(); ++i)
                    members[next[assignment[i]]++] = std::uint32_t(i);
            }
            bool empty(std::uint32_t j) const { return start[j] == start[j + 1]; }
        };

        /// A GLA step (Linz et al. 2006, §4.1): every codeword moves to its cluster's mean (sums in
        /// double, members in index order); each empty cluster takes the farthest vector from its
        /// codeword (lowest index on ties), distinct values for distinct empty clusters.
        void moveToMeans(const float* data, int dim, const NearestCodeword& search, std::vector<float>& codebook)
        {
            const std::size_t d = std::size_t(dim);
            const std::uint32_t k = std::uint32_t(codebook.size() / d);
            const Clusters clusters(search.assignment, k);
            using Range = tbb::blocked_range<std::uint32_t>;
            tbb::parallel_for(Range(0, k, 16), [&](const Range& r) {
                std::vector<double> sum(d);
                for (std::uint32_t j = r.begin(); j < r.end(); ++j)
                {
                    if (clusters.empty(j))
                        continue;
                    std::fill(sum.begin(), sum.end(), 0.0);
                    for (std::size_t m = clusters.start[j]; m < clusters.start[j + 1]; ++m)
                    {
                        const float* v = data + clusters.members[m] * d;
                        for (std::size_t c = 0; c < d; ++c)
                            sum[c] += v[c];
                    }
                    const double n = double(clusters.start[j + 1] - clusters.start[j]);
                    for (std::size_t c = 0; c < d; ++c)
                        codebook[j * d + c] = float(sum[c] / n);
                }
            });

            std::vector<std::uint32_t> empty;
            for (std::uint32_t j = 0; j < k; ++j)
                if (clusters.empty(j))
                    empty.push_back(j);
            if (empty.empty())
                return;
            const std::vector<float>& dist = search.distance;
            std::vector<std::uint32_t> candidates;
            for (std::size_t i = 0; i < dist.size(); ++i)
                if (dist[i] > 0.0f)
                    candidates.push_back(std::uint32_t(i));
            const auto farther = [&](std::uint32_t a, std::uint32_t b) {
                return dist[a] > dist[b] || (dist[a] == dist[b] && a < b);
            };
            // A strict total order, so the sorted prefix is the same with any standard library.
            std::size_t sorted = std::min(candidates.size(), empty.size() + 64);
            std::partial_sort(candidates.begin(), candidates.begin() + std::ptrdiff_t(sorted), candidates.end(),
                              farther);
            std::vector<std::uint32_t> taken;
            std::size_t next = 0;
            for (std::uint32_t j : empty)
            {
                for (; next < candidates.size(); ++next)
                {
                    if (next == sorted)
                    {
                        std::sort(candidates.begin() + std::ptrdiff_t(sorted), candidates.end(), farther);
                        sorted = candidates.size();
                    }
                    const float* v = data + candidates[next] * d;
                    const bool duplicate = std::any_of(taken.begin(), taken.end(), [&](std::uint32_t t) {
                        return std::equal(v, v + d, data + t * d);
                    });
                    if (!duplicate)
                        break;
                }
                if (next == candidates.size())
                    break; // every vector sits on a codeword: nothing left to take
                taken.push_back(candidates[next]);
                std::copy(data + candidates[next] * d, data + (candidates[next] + 1) * d, &codebook[j * d]);
                ++next;
            }
        }

        /// The modified GLA (Linz et al. 2006, §4.1.2): every codeword becomes the vector nearest to
        /// it among those assigned to it (lowest index on ties); an empty cluster's, the nearest
        /// vector of all.
        void moveToNearestInputs(const float* data, std::size_t count, int dim, const NearestCodeword& search,
                                 std::vector<float>& codebook)
        {
            const std::size_t d = std::size_t(dim);
            const std::uint32_t k = std::uint32_t(codebook.size() / d);
            const Clusters clusters(search.assignment, k);
            for (std::uint32_t j = 0; j < k; ++j)
            {
                std::uint32_t nearest = NONE;
                if (clusters.empty(j))
                {
                    float best = FLOAT_INF;
                    for (std::size_t i = 0; i < count; ++i)
                    {
                        const float dist = squaredDistance(data + i * d, &codebook[j * d], dim, best);
                        if (dist < best)
                        {
                            best = dist;
                            nearest = std::uint32_t(i);
                        }
                    }
                }
                else
                {
                    float best = FLOAT_INF;
                    for (std::size_t m = clusters.start[j]; m < clusters.start[j + 1]; ++m)
                        if (search.distance[clusters.members[m]] < best)
                        {
                            best = search.distance[clusters.members[m]];
                            nearest = clusters.members[m];
                        }
                }
                std::copy(data + nearest * d, data + (nearest + 1) * d, &codebook[j * d]);
            }
        }

        // ---- Colour ---------------------------------------------------------------------------

        // D65 white and the sRGB primaries (IEC 61966-2-1); the matrix rows sum to the white.
        constexpr double XN = 0.95047, YN = 1.0, ZN = 1.08883;
        constexpr double RGB_TO_XYZ[3][3] = {{0.4124564, 0.3575761, 0.1804375},
                                             {0.2126729, 0.7151522, 0.0721750},
                                             {0.0193339, 0.1191920, 0.9503041}};
        constexpr double XYZ_TO_RGB[3][3] = {{3.2404542, -1.5371385, -0.4985314},
                                             {-0.9692660, 1.8760108, 0.0415560},
                                             {0.0556434, -0.2040259, 1.0572252}};
        constexpr double DELTA = 6.0 / 29.0;

        /// The CIE f() with its linear segment near black, and its inverse.
        double labF(double t)
        {
            return t > DELTA * DELTA * DELTA ? std::cbrt(t) : t / (3.0 * DELTA * DELTA) + 4.0 / 29.0;
        }

        double labFInverse(double t) { return t > DELTA ? t * t * t : 3.0 * DELTA * DELTA * (t - 4.0 / 29.0); }

        std::array<float, 3> labFromLinear(double r, double g, double b)
        {
            const double x = RGB_TO_XYZ[0][0] * r + RGB_TO_XYZ[0][1] * g + RGB_TO_XYZ[0][2] * b;
            const double y = RGB_TO_XYZ[1][0] * r + RGB_TO_XYZ[1][1] * g + RGB_TO_XYZ[1][2] * b;
            const double z = RGB_TO_XYZ[2][0] * r + RGB_TO_XYZ[2][1] * g + RGB_TO_XYZ[2][2] * b;
            const double fx = labF(x / XN), fy = labF(y / YN), fz = labF(z / ZN);
            return {float(116.0 * fy - 16.0), float(500.0 * (fx - fy)), float(200.0 * (fy - fz))};
        }

        /// Linear value of every sRGB byte.
        const std::array<double, 256>& byteToLinear()
        {
            static const std::array<double, 256> table = [] {
                std::array<double, 256> t{};
                for (int i = 0; i < 256; ++i)
                    t[std::size_t(i)] = srgbByteToLinear(std::uint8_t(i));
                return t;
            }();
            return table;
        }

        std::array<float, 3> labFromBytes(const std::array<std::uint8_t, 4>& texel)
        {
            const std::array<double, 256>& lin = byteToLinear();
            return labFromLinear(lin[texel[0]], lin[texel[1]], lin[texel[2]]);
        }
    }

    GlaResult runGla(const std::vector<float>& vectors, int dimension, const GlaOptions& options)
    {
        if (dimension < 1)
            throw std::invalid_argument("runGla: dimension " + std::to_string(dimension) + " < 1");
        const std::size_t d = std::size_t(dimension);
        if (vectors.size() % d != 0)
            throw std::invalid_argument("runGla: " + std::to_string(vectors.size()) +
                                        " components is not a multiple of dimension " + std::to_string(dimension));
        if (options.codebookSize == 0)
            throw std::invalid_argument("runGla: codebookSize 0");
        if (options.maxIterations < 1)
            throw std::invalid_argument("runGla: maxIterations " + std::to_string(options.maxIterations) + " < 1");
        const std::size_t count = vectors.size() / d;
        if (count >= NONE)
            throw std::invalid_argument("runGla: " + std::to_string(count) + " vectors (at most 2^32 - 2)");
        for (std::size_t i = 0; i < vectors.size(); ++i)
            if (!std::isfinite(vectors[i]))
                throw std::invalid_argument("runGla: component " + std::to_string(i % d) + " of vector " +
                                            std::to_string(i / d) + " is not finite");

        GlaResult result;
        result.dimension = dimension;
        if (count == 0)
            return result;
        // The training set: every vector, or an evenly strided subset of maxTrainingVectors.
        std::vector<float> subset;
        const float* data = vectors.data();
        std::size_t trainCount = count;
        if (options.maxTrainingVectors > 0 && count > options.maxTrainingVectors)
        {
            trainCount = options.maxTrainingVectors;
            subset.resize(trainCount * d);
            for (std::size_t i = 0; i < trainCount; ++i)
            {
                const std::size_t from = std::size_t((unsigned __int128)i * count / trainCount);
                std::copy(data + from * d, data + (from + 1) * d, &subset[i * d]);
            }
            data = subset.data();
        }

        // Initial codewords: K distinct training vectors by a seeded partial Fisher-Yates draw.
        std::vector<std::uint32_t> distinct = distinctVectors(data, trainCount, dimension);
        const std::uint32_t k = std::uint32_t(std::min<std::size_t>(options.codebookSize, distinct.size()));
        std::mt19937_64 rng(options.seed);
        std::vector<float> codebook(k * d), previous;
        for (std::uint32_t j = 0; j < k; ++j)
        {
            std::swap(distinct[j], distinct[j + drawBelow(rng, distinct.size() - j)]);
            std::copy(data + distinct[j] * d, data + (distinct[j] + 1) * d, &codebook[j * d]);
        }
        distinct = {};

        // GLA iterations (Linz et al. 2006, §4.1): assign to the nearest codeword, move to the means.
        NearestCodeword search(data, trainCount, dimension);
        search.assign(codebook, previous);
        double mse = search.meanSquaredError();
        for (int iteration = 1; iteration <= options.maxIterations; ++iteration)
        {
            previous = codebook;
            moveToMeans(data, dimension, search, codebook);
            search.assign(codebook, previous);
            const double next = search.meanSquaredError();
            result.iterations = iteration;
            // An improvement of exactly tolerance * mse counts as converged: tolerance 0 stops at a
            // fixed point.
            const bool converged = mse - next <= options.tolerance * mse;
            mse = next;
            if (options.progress)
                options.progress(float(iteration) / float(options.maxIterations));
            if (converged)
                break;
        }

        // The modified GLA (Linz et al. 2006, §4.1.2): codewords become training vectors; reassign.
        if (options.nearestInput)
        {
            previous = codebook;
            moveToNearestInputs(data, trainCount, dimension, search, codebook);
            search.assign(codebook, previous);
            mse = search.meanSquaredError();
        }

        if (!subset.empty())
        {
            // Every vector to its nearest codeword of the subset's codebook.
            NearestCodeword all(vectors.data(), count, dimension);
            all.assign(codebook, {});
            mse = all.meanSquaredError();
            search.assignment = std::move(all.assignment);
        }

        result.codebook = std::move(codebook);
        result.assignment = std::move(search.assignment);
        result.meanSquaredError = mse;
        return result;
    }

    std::array<float, 3> srgbToLab(float r, float g, float b)
    {
        const auto linear = [](float c) { return double(srgbToLinear(std::clamp(c, 0.0f, 1.0f))); };
        return labFromLinear(linear(r), linear(g), linear(b));
    }

    std::array<float, 3> labToSrgb(float l, float a, float b)
    {
        const double fy = (l + 16.0) / 116.0, fx = fy + a / 500.0, fz = fy - b / 200.0;
        const double x = XN * labFInverse(fx), y = YN * labFInverse(fy), z = ZN * labFInverse(fz);
        std::array<float, 3> out{};
        for (int c = 0; c < 3; ++c)
        {
            const double linear = XYZ_TO_RGB[c][0] * x + XYZ_TO_RGB[c][1] * y + XYZ_TO_RGB[c][2] * z;
            out[std::size_t(c)] = std::clamp(linearToSrgb(float(std::clamp(linear, 0.0, 1.0))), 0.0f, 1.0f);
        }
        return out;
    }

    void fillTransparentTexels(BillboardTexture& texture)
    {
        // Black-pixel heuristic (Linz et al. 2006, §4.1.1): the brightest covered texel, lowest
        // index on ties.
        int brightest = -1;
        float brightestL = -FLOAT_INF;
        for (int t = 0; t < BILLBOARD_TEXELS; ++t)
        {
            const auto& texel = texture.texels[std::size_t(t)];
            if (texel[3] == 0)
                continue;
            const float l = labFromBytes(texel)[0];
            if (l > brightestL)
            {
                brightestL = l;
                brightest = t;
            }
        }
        if (brightest < 0)
            return;
        const std::array<std::uint8_t, 4> fill = texture.texels[std::size_t(brightest)];
        for (auto& texel : texture.texels)
            if (texel[3] == 0)
                std::copy(fill.begin(), fill.begin() + 3, texel.begin());
    }

    std::array<float, 3 * BILLBOARD_TEXELS> colourVector(const BillboardTexture& texture, QuantisationSpace space)
    {
        std::array<float, COLOUR_DIM> v{};
        for (std::size_t t = 0; t < std::size_t(BILLBOARD_TEXELS); ++t)
        {
            const auto& texel = texture.texels[t];
            if (space == QuantisationSpace::Lab)
            {
                const std::array<float, 3> lab = labFromBytes(texel);
                std::copy(lab.begin(), lab.end(), &v[3 * t]);
            }
            else
                for (std::size_t c = 0; c < 3; ++c)
                    v[3 * t + c] = float(texel[c] * (100.0 / 255.0));
        }
        return v;
    }

    BillboardTexture colourFromVector(const float* vector, QuantisationSpace space)
    {
        BillboardTexture out;
        for (std::size_t t = 0; t < std::size_t(BILLBOARD_TEXELS); ++t)
        {
            const float* v = vector + 3 * t;
            auto& texel = out.texels[t];
            if (space == QuantisationSpace::Lab)
            {
                const std::array<float, 3> rgb = labToSrgb(v[0], v[1], v[2]);
                for (std::size_t c = 0; c < 3; ++c)
                    texel[c] = unitToByte(rgb[c]);
            }
            else
                for (std::size_t c = 0; c < 3; ++c)
                    texel[c] = unitToByte(float(v[c] / 100.0));
            texel[3] = 255;
        }
        return out;
    }

    QuantisedBillboards quantiseBillboards(const std::vector<BillboardTexture>& billboards,
                                           const BillboardQuantisationOptions& options, const ProgressCallback& progress)
    {
        const std::size_t n = billboards.size();
        std::vector<float> colour(n * COLOUR_DIM), alpha(n * BILLBOARD_TEXELS);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t i = r.begin(); i < r.end(); ++i)
            {
                BillboardTexture filled = billboards[i];
                fillTransparentTexels(filled);
                const auto v = colourVector(filled, options.space);
                std::copy(v.begin(), v.end(), &colour[i * COLOUR_DIM]);
                for (std::size_t t = 0; t < std::size_t(BILLBOARD_TEXELS); ++t)
                    alpha[i * BILLBOARD_TEXELS + t] = filled.texels[t][3];
            }
        });

        GlaOptions gla;
        gla.maxIterations = options.maxIterations;
        gla.nearestInput = options.nearestInput;
        gla.seed = options.seed;
        gla.maxTrainingVectors = options.maxTrainingVectors;
        // The two codebooks at once (each GLA is deterministic alone); the colour one, the
        // longer, reports progress.
        GlaOptions colourOptions = gla, alphaOptions = gla;
        colourOptions.codebookSize = options.colourCodebookSize;
        colourOptions.progress = [&](float fraction) { report(progress, "vector quantisation", fraction); };
        alphaOptions.codebookSize = options.alphaCodebookSize;
        GlaResult colourGla, alphaGla;
        tbb::parallel_invoke(
            [&] {
                colourGla = runGla(colour, COLOUR_DIM, colourOptions);
                colour = {};
            },
            [&] { alphaGla = runGla(alpha, BILLBOARD_TEXELS, alphaOptions); });

        QuantisedBillboards q;
        for (std::uint32_t j = 0; j < colourGla.codebookSize(); ++j)
            q.colourCodebook.push_back(
                colourFromVector(&colourGla.codebook[j * std::size_t(COLOUR_DIM)], options.space));
        for (std::uint32_t j = 0; j < alphaGla.codebookSize(); ++j)
        {
            BillboardTexture texture; // colour 0
            for (std::size_t t = 0; t < std::size_t(BILLBOARD_TEXELS); ++t)
                texture.texels[t][3] = unitToByte(alphaGla.codebook[j * std::size_t(BILLBOARD_TEXELS) + t] / 255.0f);
            q.alphaCodebook.push_back(texture);
        }
        q.colourIndex = std::move(colourGla.assignment);
        q.alphaIndex = std::move(alphaGla.assignment);
        q.colourIterations = colourGla.iterations;
        q.alphaIterations = alphaGla.iterations;
        return q;
    }

    BillboardTexture dequantise(const QuantisedBillboards& q, std::size_t i)
    {
        BillboardTexture out = q.colourCodebook.at(q.colourIndex.at(i));
        const BillboardTexture& alpha = q.alphaCodebook.at(q.alphaIndex.at(i));
        for (std::size_t t = 0; t < std::size_t(BILLBOARD_TEXELS); ++t)
            out.texels[t][3] = alpha.texels[t][3];
        return out;
    }

    double billboardPsnr(const std::vector<BillboardTexture>& original, const std::vector<BillboardTexture>& decoded,
                         bool alphaOnly)
    {
        if (original.size() != decoded.size())
            throw std::invalid_argument("billboardPsnr: " + std::to_string(original.size()) + " and " +
                                        std::to_string(decoded.size()) + " billboards");
        std::uint64_t sum = 0, samples = 0;
        for (std::size_t i = 0; i < original.size(); ++i)
            for (std::size_t t = 0; t < std::size_t(BILLBOARD_TEXELS); ++t)
                for (std::size_t c = alphaOnly ? 3 : 0; c < 4; ++c)
                {
                    const int e = int(original[i].texels[t][c]) - int(decoded[i].texels[t][c]);
                    sum += std::uint64_t(e * e);
                    ++samples;
                }
        if (sum == 0)
            return DOUBLE_INF;
        return 10.0 * std::log10(255.0 * 255.0 / (double(sum) / double(samples)));
    }

    double billboardColourRms(const std::vector<BillboardTexture>& original,
                              const std::vector<BillboardTexture>& decoded)
    {
        if (original.size() != decoded.size())
            throw std::invalid_argument("billboardColourRms: " + std::to_string(original.size()) + " and " +
                                        std::to_string(decoded.size()) + " billboards");
        std::uint64_t sum[3] = {0, 0, 0}, covered = 0;
        for (std::size_t i = 0; i < original.size(); ++i)
            for (std::size_t t = 0; t < std::size_t(BILLBOARD_TEXELS); ++t)
            {
                if (original[i].texels[t][3] == 0)
                    continue;
                ++covered;
                for (std::size_t c = 0; c < 3; ++c)
                {
                    const int e = int(original[i].texels[t][c]) - int(decoded[i].texels[t][c]);
                    sum[c] += std::uint64_t(e * e);
                }
            }
        if (covered == 0)
            return 0.0;
        double rms = 0.0;
        for (std::uint64_t s : sum)
            rms += std::sqrt(double(s) / double(covered));
        return rms / 3.0;
    }
}
