// FLIP, the LDR version.
//
// This work is based on:
//   Pontus Andersson, Jim Nilsson, Tomas Akenine-Moller, Magnus Oskarsson, Kalle Astrom,
//   Mark D. Fairchild: "FLIP: A Difference Evaluator for Alternating Images",
//   Proc. ACM Comput. Graph. Interact. Tech. 3(2) (HPG 2020).
// Written from the paper's description with its published default parameters.
//
// Per image: sRGB -> linear RGB -> XYZ (D65) -> YCxCz; each opponent channel is filtered
// with its contrast sensitivity function (CSF, a sum of Gaussians in degrees of visual
// angle); the result goes back to linear RGB, is clamped to [0, 1] and converted to
// CIELab with the Hunt adjustment. Independently, edge and point detectors run on the
// normalised achromatic channel. Per pixel the colour difference (HyAB, compressed and
// remapped) is raised to the power (1 - feature difference).
//
// Choices the paper leaves open, documented here:
// - Borders: clamp-to-edge in every filter.
// - One CSF kernel radius for all three channels, from the widest Gaussian (b = 0.04).
// - The feature detectors' standard deviation is sigma = 0.5 * w * ppd with w = 0.082
//   degrees, w being the peak-to-trough width (2 sigma) of the edge detector.
// - Where the colour difference is exactly 0 the error is 0 (avoids 0^0 = 1).
// - The reported median is the plain (unweighted) median of the per-pixel errors.
// FLIP is symmetric in its inputs: every per-pixel term is an absolute difference of
// quantities computed the same way for both images, so flip(a, b) == flip(b, a) exactly.
#include "TreeLod/ImageMetrics.h"

#include "MetricsSupport.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

namespace TreeLod
{
    namespace
    {
        constexpr double kPi = 3.14159265358979323846;

        // Published defaults (paper, LDR-FLIP).
        constexpr float kQc = 0.7f;   // colour difference exponent
        constexpr float kPc = 0.4f;   // remap breakpoint (fraction of cmax)
        constexpr float kPt = 0.95f;  // remapped value at the breakpoint
        // Feature difference exponent qf = 0.5, applied as a square root below.
        constexpr double kFeatureWidth = 0.082; // degrees, peak to trough of the edge detector

        // CSF as a sum of Gaussians per opponent channel (a1, b1, a2, b2).
        struct CsfParams
        {
            double a1, b1, a2, b2;
        };
        constexpr CsfParams kCsfAchromatic{1.0, 0.0047, 0.0, 1e-5};
        constexpr CsfParams kCsfRedGreen{1.0, 0.0053, 0.0, 1e-5};
        constexpr CsfParams kCsfBlueYellow{34.1, 0.04, 13.5, 0.025};

        // Linear sRGB primaries <-> CIE XYZ, D65 white.
        inline void rgbToXyz(float r, float g, float b, float& x, float& y, float& z)
        {
            x = 0.4124564f * r + 0.3575761f * g + 0.1804375f * b;
            y = 0.2126729f * r + 0.7151522f * g + 0.0721750f * b;
            z = 0.0193339f * r + 0.1191920f * g + 0.9503041f * b;
        }

        inline void xyzToRgb(float x, float y, float z, float& r, float& g, float& b)
        {
            r = 3.2404542f * x - 1.5371385f * y - 0.4985314f * z;
            g = -0.9692660f * x + 1.8760108f * y + 0.0415560f * z;
            b = 0.0556434f * x - 0.2040259f * y + 1.0572252f * z;
        }

        // Reference white: XYZ of linear RGB (1, 1, 1).
        constexpr float kWhiteX = 0.4124564f + 0.3575761f + 0.1804375f;
        constexpr float kWhiteY = 0.2126729f + 0.7151522f + 0.0721750f;
        constexpr float kWhiteZ = 0.0193339f + 0.1191920f + 0.9503041f;

        /// Cube root of t > 0: a bit-level first guess (exponent / 3) refined by three
        /// Newton steps, accurate to float precision; several times faster than cbrtf.
        inline float cubeRoot(float t)
        {
            std::uint32_t bits;
            std::memcpy(&bits, &t, sizeof bits);
            bits = bits / 3 + 709921077u; // 127 * 2^23 * 2 / 3, the exponent bias kept
            float y;
            std::memcpy(&y, &bits, sizeof y);
            for (int i = 0; i < 3; ++i)
                y = (2.0f * y + t / (y * y)) * (1.0f / 3.0f);
            return y;
        }

        inline float labF(float t)
        {
            constexpr float delta = 6.0f / 29.0f;
            return t > delta * delta * delta ? cubeRoot(t) : t / (3.0f * delta * delta) + 4.0f / 29.0f;
        }

        /// Linear RGB in [0, 1] -> CIELab with the Hunt adjustment (a, b scaled by 0.01 L).
        inline void rgbToHuntLab(float r, float g, float b, float& L, float& A, float& B)
        {
            float x, y, z;
            rgbToXyz(r, g, b, x, y, z);
            const float fx = labF(x / kWhiteX), fy = labF(y / kWhiteY), fz = labF(z / kWhiteZ);
            L = 116.0f * fy - 16.0f;
            A = 0.01f * L * (500.0f * (fx - fy));
            B = 0.01f * L * (200.0f * (fy - fz));
        }

        inline float hyab(float L1, float A1, float B1, float L2, float A2, float B2)
        {
            const float da = A1 - A2, db = B1 - B2;
            return std::fabs(L1 - L2) + std::sqrt(da * da + db * db);
        }

        /// cmax: the compressed HyAB distance between Hunt-adjusted pure green and blue.
        float maxColourDifference()
        {
            float L1, A1, B1, L2, A2, B2;
            rgbToHuntLab(0.0f, 1.0f, 0.0f, L1, A1, B1);
            rgbToHuntLab(0.0f, 0.0f, 1.0f, L2, A2, B2);
            return std::pow(hyab(L1, A1, B1, L2, A2, B2), kQc);
        }

        /// A row-major float plane.
        struct Plane
        {
            int width = 0, height = 0;
            std::vector<float> v;
            Plane(int w, int h) : width(w), height(h), v(std::size_t(w) * h) {}
            float* row(int y) { return v.data() + std::size_t(y) * width; }
            const float* row(int y) const { return v.data() + std::size_t(y) * width; }
        };

        using Kernel = std::vector<float>; // 2r + 1 taps, centre at index r

        template <typename Body> void forRows(int height, const Body& body)
        {
            tbb::parallel_for(tbb::blocked_range<int>(0, height, 16), [&](const tbb::blocked_range<int>& range) {
                body(range.begin(), range.end());
            });
        }

        /// Horizontal convolution of `in` with each kernel of `kernels` (all the same size),
        /// clamp-to-edge; one output plane per kernel.
        void convolveRows(const Plane& in, const std::vector<const Kernel*>& kernels, const std::vector<Plane*>& out)
        {
            const int w = in.width;
            const int r = int(kernels[0]->size() / 2);
            forRows(in.height, [&](int y0, int y1) {
                std::vector<float> padded(std::size_t(w) + 2 * r);
                for (int y = y0; y < y1; ++y)
                {
                    const float* src = in.row(y);
                    for (int i = 0; i < r; ++i)
                    {
                        padded[std::size_t(i)] = src[0];
                        padded[std::size_t(w + r + i)] = src[w - 1];
                    }
                    std::copy(src, src + w, padded.begin() + r);
                    for (std::size_t k = 0; k < kernels.size(); ++k)
                    {
                        const Kernel& kernel = *kernels[k];
                        float* dst = out[k]->row(y);
                        std::fill(dst, dst + w, 0.0f);
                        for (int j = 0; j <= 2 * r; ++j)
                        {
                            const float c = kernel[std::size_t(j)];
                            const float* p = padded.data() + j;
                            for (int x = 0; x < w; ++x)
                                dst[x] += c * p[x];
                        }
                    }
                }
            });
        }

        /// Vertical convolution of one row of `in`, clamp-to-edge, into `dst`.
        inline void convolveColumn(const Plane& in, const Kernel& kernel, int y, float* dst)
        {
            const int w = in.width, h = in.height;
            const int r = int(kernel.size() / 2);
            std::fill(dst, dst + w, 0.0f);
            for (int j = -r; j <= r; ++j)
            {
                const float c = kernel[std::size_t(j + r)];
                const float* src = in.row(std::clamp(y + j, 0, h - 1));
                for (int x = 0; x < w; ++x)
                    dst[x] += c * src[x];
            }
        }

        /// Sampled Gaussian exp(-pi^2 (x / ppd)^2 / b) for x = -r..r pixels (CSF term).
        Kernel csfGaussian(double b, double ppd, int r)
        {
            Kernel k(std::size_t(2 * r + 1));
            for (int i = -r; i <= r; ++i)
            {
                const double d = double(i) / ppd;
                k[std::size_t(i + r)] = float(std::exp(-kPi * kPi * d * d / b));
            }
            return k;
        }

        double sum(const Kernel& k)
        {
            double s = 0.0;
            for (float v : k)
                s += v;
            return s;
        }

        Kernel scaled(Kernel k, double factor)
        {
            for (float& v : k)
                v = float(v * factor);
            return k;
        }

        /// The kernels for one image size and ppd.
        struct Kernels
        {
            // CSF. The 2D kernel of a channel is c1 G1(x)G1(y) + c2 G2(x)G2(y) with
            // ci = ai sqrt(pi / bi), normalised to sum 1; separable term by term.
            Kernel achromatic, redGreen;      // normalised 1D Gaussians (a2 = 0 for these)
            Kernel blueYellow1, blueYellow2;  // 1D Gaussians of the two terms, each of sum 1
            float blueYellowWeight1 = 1.0f, blueYellowWeight2 = 0.0f;
            // Feature detectors: Gaussian (sum 1), first and second derivative.
            Kernel gauss, edge, point;
        };

        Kernels makeKernels(double ppd)
        {
            Kernels k;
            // paper: CSF radius from the widest Gaussian, 3 standard deviations.
            const double bMax = std::max({kCsfAchromatic.b1, kCsfAchromatic.b2, kCsfRedGreen.b1, kCsfRedGreen.b2,
                                          kCsfBlueYellow.b1, kCsfBlueYellow.b2});
            const int r = int(std::ceil(3.0 * std::sqrt(bMax / (2.0 * kPi * kPi)) * ppd));

            Kernel a = csfGaussian(kCsfAchromatic.b1, ppd, r);
            k.achromatic = scaled(a, 1.0 / sum(a));
            Kernel rg = csfGaussian(kCsfRedGreen.b1, ppd, r);
            k.redGreen = scaled(rg, 1.0 / sum(rg));

            Kernel by1 = csfGaussian(kCsfBlueYellow.b1, ppd, r);
            Kernel by2 = csfGaussian(kCsfBlueYellow.b2, ppd, r);
            const double s1 = sum(by1), s2 = sum(by2);
            const double c1 = kCsfBlueYellow.a1 * std::sqrt(kPi / kCsfBlueYellow.b1) * s1 * s1;
            const double c2 = kCsfBlueYellow.a2 * std::sqrt(kPi / kCsfBlueYellow.b2) * s2 * s2;
            k.blueYellow1 = scaled(by1, 1.0 / s1);
            k.blueYellow2 = scaled(by2, 1.0 / s2);
            k.blueYellowWeight1 = float(c1 / (c1 + c2));
            k.blueYellowWeight2 = float(c2 / (c1 + c2));

            // paper: edge and point detectors, first and second derivative of a Gaussian.
            const double sigma = 0.5 * kFeatureWidth * ppd;
            const int rf = std::max(1, int(std::ceil(3.0 * sigma)));
            k.gauss.resize(std::size_t(2 * rf + 1));
            k.edge.resize(k.gauss.size());
            k.point.resize(k.gauss.size());
            double gSum = 0.0, edgePositive = 0.0, pointPositive = 0.0, pointNegative = 0.0;
            for (int i = -rf; i <= rf; ++i)
            {
                const double x = double(i);
                const double g = std::exp(-x * x / (2.0 * sigma * sigma));
                const double e = -x * g;
                const double p = (x * x / (sigma * sigma) - 1.0) * g;
                k.gauss[std::size_t(i + rf)] = float(g);
                k.edge[std::size_t(i + rf)] = float(e);
                k.point[std::size_t(i + rf)] = float(p);
                gSum += g;
                edgePositive += e > 0.0 ? e : 0.0;
                (p > 0.0 ? pointPositive : pointNegative) += p;
            }
            // Gaussian sums to 1; edge kernel scaled so its positive part sums to 1 (its
            // negative part then sums to -1); point kernel's positive part to 1 and its
            // negative part to -1 separately. The 2D sums factor the same way, since the
            // perpendicular factor is the unit-sum Gaussian.
            for (std::size_t i = 0; i < k.gauss.size(); ++i)
            {
                k.gauss[i] = float(k.gauss[i] / gSum);
                k.edge[i] = float(k.edge[i] / edgePositive);
                k.point[i] = float(k.point[i] > 0.0f ? k.point[i] / pointPositive : k.point[i] / -pointNegative);
            }
            return k;
        }

        /// What the per-pixel comparison needs from one image.
        struct Analysis
        {
            Plane L, A, B;      // filtered colour, Hunt-adjusted CIELab
            Plane edge, point;  // feature magnitudes
            Analysis(int w, int h) : L(w, h), A(w, h), B(w, h), edge(w, h), point(w, h) {}
        };

        void analyse(const Image& image, const Kernels& k, Analysis& out)
        {
            const int w = image.width, h = image.height;
            Plane y(w, h), cx(w, h), cz(w, h), luminance(w, h);

            // sRGB -> linear -> XYZ -> YCxCz; luminance = normalised achromatic channel.
            forRows(h, [&](int y0, int y1) {
                for (int row = y0; row < y1; ++row)
                {
                    const glm::vec4* src = &image.pixels[std::size_t(row) * w];
                    float* py = y.row(row);
                    float* px = cx.row(row);
                    float* pz = cz.row(row);
                    float* pl = luminance.row(row);
                    for (int x = 0; x < w; ++x)
                    {
                        float X, Y, Z;
                        rgbToXyz(srgbToLinear(src[x].r), srgbToLinear(src[x].g), srgbToLinear(src[x].b), X, Y, Z);
                        const float xr = X / kWhiteX, yr = Y / kWhiteY, zr = Z / kWhiteZ;
                        py[x] = 116.0f * yr - 16.0f;
                        px[x] = 500.0f * (xr - yr);
                        pz[x] = 200.0f * (yr - zr);
                        pl[x] = (py[x] + 16.0f) / 116.0f;
                    }
                }
            });

            // CSF filtering per opponent channel (horizontal, then vertical).
            Plane ty(w, h), tx(w, h), tz1(w, h), tz2(w, h);
            convolveRows(y, {&k.achromatic}, {&ty});
            convolveRows(cx, {&k.redGreen}, {&tx});
            convolveRows(cz, {&k.blueYellow1, &k.blueYellow2}, {&tz1, &tz2});

            // Feature detectors, horizontal pass.
            Plane fg(w, h), fe(w, h), fp(w, h);
            convolveRows(luminance, {&k.gauss, &k.edge, &k.point}, {&fg, &fe, &fp});

            forRows(h, [&](int y0, int y1) {
                std::vector<float> fy(std::size_t(w) * 2), fz1(w), fz2(w);
                std::vector<float> ex(w), ey(w), px(w), py(w);
                for (int row = y0; row < y1; ++row)
                {
                    convolveColumn(ty, k.achromatic, row, fy.data());
                    convolveColumn(tx, k.redGreen, row, fy.data() + w);
                    convolveColumn(tz1, k.blueYellow1, row, fz1.data());
                    convolveColumn(tz2, k.blueYellow2, row, fz2.data());
                    float* L = out.L.row(row);
                    float* A = out.A.row(row);
                    float* B = out.B.row(row);
                    for (int x = 0; x < w; ++x)
                    {
                        const float fyv = fy[std::size_t(x)], fxv = fy[std::size_t(w + x)];
                        const float fzv = k.blueYellowWeight1 * fz1[std::size_t(x)] + k.blueYellowWeight2 * fz2[std::size_t(x)];
                        // YCxCz -> XYZ -> linear RGB, clamped to [0, 1].
                        const float yr = (fyv + 16.0f) / 116.0f;
                        const float X = (yr + fxv / 500.0f) * kWhiteX, Y = yr * kWhiteY, Z = (yr - fzv / 200.0f) * kWhiteZ;
                        float r, g, b;
                        xyzToRgb(X, Y, Z, r, g, b);
                        rgbToHuntLab(std::clamp(r, 0.0f, 1.0f), std::clamp(g, 0.0f, 1.0f), std::clamp(b, 0.0f, 1.0f),
                                     L[x], A[x], B[x]);
                    }

                    convolveColumn(fe, k.gauss, row, ex.data());
                    convolveColumn(fg, k.edge, row, ey.data());
                    convolveColumn(fp, k.gauss, row, px.data());
                    convolveColumn(fg, k.point, row, py.data());
                    float* edge = out.edge.row(row);
                    float* point = out.point.row(row);
                    for (int x = 0; x < w; ++x)
                    {
                        edge[x] = std::sqrt(ex[std::size_t(x)] * ex[std::size_t(x)] + ey[std::size_t(x)] * ey[std::size_t(x)]);
                        point[x] = std::sqrt(px[std::size_t(x)] * px[std::size_t(x)] + py[std::size_t(x)] * py[std::size_t(x)]);
                    }
                }
            });
        }
    }

    double flipDefaultPixelsPerDegree()
    {
        // distance * (pixels / width) * (pi / 180): 0.7 m, 3840 pixels over 0.7 m.
        const double distance = 0.7, width = 0.7, pixels = 3840.0;
        return distance * (pixels / width) * (kPi / 180.0);
    }

    namespace
    {
        /// The per-pixel FLIP of two analysed images of one size and kernels.
        FlipResult compare(const Analysis& ref, const Analysis& tst, bool keepErrorMap)
        {
            const int w = ref.L.width, h = ref.L.height;
            const float cmax = maxColourDifference();
            const float breakpoint = kPc * cmax;
            std::vector<float> errors(std::size_t(w) * h);
            std::vector<double> rowSums(static_cast<std::size_t>(h));
            std::vector<float> rowMax(static_cast<std::size_t>(h));
            forRows(h, [&](int y0, int y1) {
                for (int y = y0; y < y1; ++y)
                {
                    double rowSum = 0.0;
                    float rowPeak = 0.0f;
                    for (int x = 0; x < w; ++x)
                    {
                        const std::size_t i = std::size_t(y) * w + x;
                        // Colour: compressed HyAB, remapped so that [0, pc cmax] -> [0, pt] and
                        // [pc cmax, cmax] -> [pt, 1].
                        const float d = std::pow(hyab(ref.L.v[i], ref.A.v[i], ref.B.v[i], tst.L.v[i], tst.A.v[i], tst.B.v[i]), kQc);
                        float colour = d < breakpoint ? (kPt / breakpoint) * d
                                                      : kPt + (d - breakpoint) / (cmax - breakpoint) * (1.0f - kPt);
                        colour = std::min(colour, 1.0f);
                        // Features: largest edge or point magnitude difference, normalised by sqrt 2.
                        const float fd = std::max(std::fabs(ref.edge.v[i] - tst.edge.v[i]), std::fabs(ref.point.v[i] - tst.point.v[i]));
                        const float feature = std::min(std::sqrt(fd / std::sqrt(2.0f)), 1.0f); // ^qf, qf = 0.5
                        const float e = colour > 0.0f ? std::pow(colour, 1.0f - feature) : 0.0f;
                        errors[i] = e;
                        rowSum += e;
                        rowPeak = std::max(rowPeak, e);
                    }
                    rowSums[std::size_t(y)] = rowSum;
                    rowMax[std::size_t(y)] = rowPeak;
                }
            });

            FlipResult result;
            result.width = w;
            result.height = h;
            double total = 0.0;
            for (int y = 0; y < h; ++y)
            {
                total += rowSums[std::size_t(y)];
                result.max = std::max(result.max, double(rowMax[std::size_t(y)]));
            }
            result.mean = total / double(errors.size());

            std::vector<float> sorted = errors;
            const std::size_t mid = sorted.size() / 2;
            std::nth_element(sorted.begin(), sorted.begin() + std::ptrdiff_t(mid), sorted.end());
            double median = sorted[mid];
            if (sorted.size() % 2 == 0)
                median = 0.5 * (median + *std::max_element(sorted.begin(), sorted.begin() + std::ptrdiff_t(mid)));
            result.weightedMedian = median;

            if (keepErrorMap)
                result.errorMap = std::move(errors);
            return result;
        }
    }

    struct FlipReference::Analysed
    {
        Kernels kernels;
        Analysis analysis;
        double pixelsPerDegree = 0.0;
    };

    int FlipReference::width() const { return analysed ? analysed->analysis.L.width : 0; }
    int FlipReference::height() const { return analysed ? analysed->analysis.L.height : 0; }

    Result<FlipReference> FlipReference::make(const Image& reference, const FlipOptions& options)
    {
        if (auto error = checkComparable("FLIP", reference, reference))
            return *error;
        const double ppd = options.pixelsPerDegree == 0.0 ? flipDefaultPixelsPerDegree() : options.pixelsPerDegree;
        if (!(ppd > 0.0) || !(ppd <= 10000.0))
            return fail("", "FLIP", "pixels per degree must be in (0, 10000], got " + std::to_string(ppd));
        auto analysed =
            std::make_shared<Analysed>(Analysed{makeKernels(ppd), Analysis(reference.width, reference.height), ppd});
        analyse(reference, analysed->kernels, analysed->analysis);
        FlipReference prepared;
        prepared.analysed = std::move(analysed);
        return prepared;
    }

    Result<FlipResult> flip(const Image& reference, const Image& test, const FlipOptions& options)
    {
        if (auto error = checkComparable("FLIP", reference, test))
            return *error;
        Result<FlipReference> prepared = FlipReference::make(reference, options);
        if (!prepared)
            return prepared.error();
        return flip(*prepared, test, options.keepErrorMap);
    }

    Result<FlipResult> flip(const FlipReference& reference, const Image& test, bool keepErrorMap)
    {
        if (!reference.analysed)
            return fail("", "FLIP", "the reference was not prepared");
        const int w = reference.width(), h = reference.height();
        if (auto error = checkComparable("FLIP", w, h, test))
            return *error;
        Analysis tst(w, h);
        analyse(test, reference.analysed->kernels, tst);
        return compare(reference.analysed->analysis, tst, keepErrorMap);
    }

    Result<FlipResult> flip(const FlipReference& reference, const FlipReference& test, bool keepErrorMap)
    {
        if (!reference.analysed || !test.analysed)
            return fail("", "FLIP", "the reference or the test image was not prepared");
        if (reference.width() != test.width() || reference.height() != test.height())
            return fail("", "FLIP",
                        "images differ in size: " + std::to_string(reference.width()) + "x" +
                            std::to_string(reference.height()) + " vs " + std::to_string(test.width()) + "x" +
                            std::to_string(test.height()));
        if (reference.analysed->pixelsPerDegree != test.analysed->pixelsPerDegree)
            return fail("", "FLIP", "the two images were prepared for different pixels per degree");
        return compare(reference.analysed->analysis, test.analysed->analysis, keepErrorMap);
    }

    Image flipHeatmap(const FlipResult& result)
    {
        if (result.width <= 0 || result.height <= 0 ||
            result.errorMap.size() != std::size_t(result.width) * result.height)
            return Image();
        // Magma-like control points (display-encoded) at t = 0, 0.1, ..., 1.
        static const std::array<glm::vec3, 11> kMap = {
            glm::vec3(0.000f, 0.000f, 0.016f), glm::vec3(0.055f, 0.043f, 0.169f), glm::vec3(0.133f, 0.067f, 0.314f),
            glm::vec3(0.231f, 0.059f, 0.439f), glm::vec3(0.392f, 0.102f, 0.502f), glm::vec3(0.549f, 0.161f, 0.506f),
            glm::vec3(0.718f, 0.216f, 0.475f), glm::vec3(0.871f, 0.286f, 0.408f), glm::vec3(0.969f, 0.439f, 0.361f),
            glm::vec3(0.996f, 0.663f, 0.451f), glm::vec3(0.988f, 0.992f, 0.749f)};
        Image out(result.width, result.height);
        for (std::size_t i = 0; i < result.errorMap.size(); ++i)
        {
            float t = result.errorMap[i];
            t = std::isnan(t) ? 0.0f : std::clamp(t, 0.0f, 1.0f) * 10.0f;
            const int j = std::min(int(t), 9);
            const glm::vec3 c = glm::mix(kMap[std::size_t(j)], kMap[std::size_t(j) + 1], t - float(j));
            out.pixels[i] = glm::vec4(c, 1.0f);
        }
        return out;
    }
}
