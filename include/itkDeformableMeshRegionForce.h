/*=========================================================================
 *
 *  Copyright NumFOCUS
 *
 *  Licensed under the Apache License, Version 2.0 (the "License");
 *  you may not use this file except in compliance with the License.
 *  You may obtain a copy of the License at
 *
 *         http://www.apache.org/licenses/LICENSE-2.0.txt
 *
 *  Unless required by applicable law or agreed to in writing, software
 *  distributed under the License is distributed on an "AS IS" BASIS,
 *  WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
 *  See the License for the specific language governing permissions and
 *  limitations under the License.
 *
 *=========================================================================*/
#ifndef itkDeformableMeshRegionForce_h
#define itkDeformableMeshRegionForce_h

#include "itkImage.h"
#include "itkMatrix.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

namespace itk
{
namespace DeformableMeshFilterDetail
{

/** The matrix M that maps a physical point x to the continuous index
 * M (x - origin) of \a image (the inverse of direction times spacing): the
 * transform both the force sampler and the intensity sampler precompute. */
template <typename TImage>
void
PhysicalToIndexMatrix(const TImage * image, double matrix[3][3])
{
  // A 2-D image is the slice z = 0 of a 3-D one: index z is physical z.
  constexpr unsigned int dimension = TImage::ImageDimension;
  static_assert(dimension == 2 || dimension == 3, "2-D or 3-D images only");
  Matrix<double, 3, 3> indexToPhysical;
  indexToPhysical.SetIdentity();
  for (unsigned int r = 0; r < dimension; ++r)
  {
    for (unsigned int c = 0; c < dimension; ++c)
    {
      indexToPhysical(r, c) = image->GetDirection()(r, c) * image->GetSpacing()[c];
    }
  }
  const vnl_matrix<double> physicalToIndex = indexToPhysical.GetInverse().as_matrix();
  for (unsigned int r = 0; r < 3; ++r)
  {
    for (unsigned int c = 0; c < 3; ++c)
    {
      matrix[r][c] = physicalToIndex(r, c);
    }
  }
}

/** The value of rank \a k (0-based) among \a values, none of them NaN: the
 * value std::nth_element would put at position k. The same value, found
 * with less work on large arrays: a regular subsample of a sixteenth of
 * the values brackets rank k between two thresholds (with a margin of
 * several standard deviations of the sample's quantile), one pass counts
 * the values below the bracket and those equal to its ends and keeps those
 * strictly within it, and the selection runs among the kept ones when the
 * counts show that rank k lies there (ranks are exact: the thresholds only
 * decide which values are looked at); otherwise, as on small arrays, among
 * all of them. \a values may be reordered. */
template <typename T>
T
SelectRank(std::vector<T> & values, size_t k)
{
  static_assert(std::is_floating_point_v<T>, "floating-point values");
  const size_t     n = values.size();
  constexpr size_t stride = 16;
  if (n < 64 * stride)
  {
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
    return values[k];
  }
  std::vector<T> sample;
  sample.reserve(n / stride + 1);
  for (size_t i = stride / 2; i < n; i += stride)
  {
    sample.push_back(values[i]);
  }
  const auto   m = static_cast<double>(sample.size());
  const double q = (static_cast<double>(k) + 0.5) / static_cast<double>(n);
  // Five standard deviations of the sample quantile's rank, plus a part of
  // the sample for the difference between subsample and array.
  const double margin = 5.0 * std::sqrt(m * q * (1.0 - q)) + 0.01 * m + 4.0;
  const double centre = q * m;
  const bool   hasLower = centre - margin >= 0.0;
  const bool   hasUpper = centre + margin <= m - 1.0;
  T            lower{};
  T            upper{};
  if (hasLower)
  {
    const auto at = sample.begin() + static_cast<std::ptrdiff_t>(centre - margin);
    std::nth_element(sample.begin(), at, sample.end());
    lower = *at;
  }
  if (hasUpper)
  {
    const auto at = sample.begin() + static_cast<std::ptrdiff_t>(centre + margin);
    std::nth_element(sample.begin(), at, sample.end());
    upper = *at;
  }
  // Values below the bracket are counted, values equal to one of its ends
  // counted (plateaus: a binary image has few distinct values), values
  // strictly inside it kept.
  size_t         below = 0;
  size_t         equalLower = 0;
  size_t         equalUpper = 0;
  std::vector<T> kept;
  kept.reserve(static_cast<size_t>(2.0 * margin * stride) + 64);
  const bool sameEnds = hasLower && hasUpper && !(lower < upper);
  for (const T value : values)
  {
    if (hasLower && !(lower < value))
    {
      below += value < lower;
      equalLower += !(value < lower);
    }
    else if (!hasUpper || value < upper)
    {
      kept.push_back(value);
    }
    else
    {
      equalUpper += !(upper < value);
    }
  }
  // Ranks: [0, below) below the bracket, then the lower end's copies, the
  // kept values, the upper end's copies (none apart when both ends are one
  // value).
  if (k >= below && k - below < equalLower)
  {
    return lower;
  }
  const size_t firstKept = below + equalLower;
  if (k >= firstKept && k - firstKept < kept.size())
  {
    const auto at = kept.begin() + static_cast<std::ptrdiff_t>(k - firstKept);
    std::nth_element(kept.begin(), at, kept.end());
    return *at;
  }
  const size_t firstUpper = firstKept + kept.size();
  if (!sameEnds && hasUpper && k >= firstUpper && k - firstUpper < equalUpper)
  {
    return upper;
  }
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

/** \class IntensitySampler
 * \brief Trilinear samples of a scalar image at physical points, read
 * through its buffer with the physical-to-index transform precomputed.
 *
 * Same inside test as itk::LinearInterpolateImageFunction (half a voxel
 * beyond the first and last voxel centres, values clamped at the border);
 * Sample() returns NaN outside.
 * \ingroup ExplicitDeformableModel
 */
class IntensitySampler
{
public:
  using ImageType = Image<float, 3>;

  void
  SetImage(const ImageType * image)
  {
    m_Buffer = image->GetBufferPointer();
    const auto region = image->GetBufferedRegion();
    PhysicalToIndexMatrix(image, m_Matrix);
    for (unsigned int r = 0; r < 3; ++r)
    {
      m_Size[r] = static_cast<int64_t>(region.GetSize()[r]);
    }
    m_Flat = m_Size[2] == 1;
    for (unsigned int r = 0; r < 3; ++r)
    {
      m_Offset[r] = static_cast<double>(region.GetIndex()[r]);
      for (unsigned int c = 0; c < 3; ++c)
      {
        m_Offset[r] += m_Matrix[r][c] * image->GetOrigin()[c];
      }
    }
    // A 2-D image embedded in 3-D (the contours' case) whose transform
    // leaves z alone exactly: the in-plane index needs only the x and y
    // columns, and index z is physical z (the same values as the general
    // product, whose z terms are exact zeros).
    m_Planar = m_Flat && m_Matrix[0][2] == 0.0 && m_Matrix[1][2] == 0.0 && m_Matrix[2][0] == 0.0 &&
               m_Matrix[2][1] == 0.0 && m_Matrix[2][2] == 1.0 && m_Offset[2] == 0.0;
  }

  /** The trilinear sample at physical point x; NaN outside the image. */
  double
  Sample(const double * x) const
  {
    if (m_Flat)
    {
      return this->SampleFlat(x);
    }
    double  c[3];
    int64_t base[3];
    double  w[3];
    for (unsigned int r = 0; r < 3; ++r)
    {
      c[r] = m_Matrix[r][0] * x[0] + m_Matrix[r][1] * x[1] + m_Matrix[r][2] * x[2] - m_Offset[r];
      if (!(c[r] >= -0.5 && c[r] < static_cast<double>(m_Size[r]) - 0.5))
      {
        return std::numeric_limits<double>::quiet_NaN();
      }
      const double f = std::floor(c[r]);
      base[r] = static_cast<int64_t>(f);
      w[r] = c[r] - f;
    }
    int64_t lo[3];
    int64_t hi[3];
    for (unsigned int r = 0; r < 3; ++r)
    {
      lo[r] = std::max<int64_t>(base[r], 0);
      hi[r] = std::min<int64_t>(base[r] + 1, m_Size[r] - 1);
    }
    const int64_t sy = m_Size[0];
    const int64_t sz = m_Size[0] * m_Size[1];
    const auto at = [&](int64_t i, int64_t j, int64_t k) { return static_cast<double>(m_Buffer[i + sy * j + sz * k]); };
    const double c00 = at(lo[0], lo[1], lo[2]) + w[0] * (at(hi[0], lo[1], lo[2]) - at(lo[0], lo[1], lo[2]));
    const double c10 = at(lo[0], hi[1], lo[2]) + w[0] * (at(hi[0], hi[1], lo[2]) - at(lo[0], hi[1], lo[2]));
    const double c01 = at(lo[0], lo[1], hi[2]) + w[0] * (at(hi[0], lo[1], hi[2]) - at(lo[0], lo[1], hi[2]));
    const double c11 = at(lo[0], hi[1], hi[2]) + w[0] * (at(hi[0], hi[1], hi[2]) - at(lo[0], hi[1], hi[2]));
    const double c0 = c00 + w[1] * (c10 - c00);
    const double c1 = c01 + w[1] * (c11 - c01);
    return c0 + w[2] * (c1 - c0);
  }

private:
  /** Sample() on an image of one slice (a 2-D image embedded in 3-D, the
   * contours' case): both z neighbours are that slice, so the trilinear
   * value is its bilinear one (c0 + w (c0 - c0) is c0 exactly); the same
   * value as the general path, with half of its loads and arithmetic. */
  double
  SampleFlat(const double * x) const
  {
    double c[3];
    if (m_Planar)
    {
      for (unsigned int r = 0; r < 2; ++r)
      {
        c[r] = m_Matrix[r][0] * x[0] + m_Matrix[r][1] * x[1] - m_Offset[r];
      }
      c[2] = x[2];
    }
    else
    {
      for (unsigned int r = 0; r < 3; ++r)
      {
        c[r] = m_Matrix[r][0] * x[0] + m_Matrix[r][1] * x[1] + m_Matrix[r][2] * x[2] - m_Offset[r];
      }
    }
    if (!(c[0] >= -0.5 && c[0] < static_cast<double>(m_Size[0]) - 0.5 && c[1] >= -0.5 &&
          c[1] < static_cast<double>(m_Size[1]) - 0.5 && c[2] >= -0.5 && c[2] < 0.5))
    {
      return std::numeric_limits<double>::quiet_NaN();
    }
    const double  f0 = std::floor(c[0]);
    const double  f1 = std::floor(c[1]);
    const auto    b0 = static_cast<int64_t>(f0);
    const auto    b1 = static_cast<int64_t>(f1);
    const double  w0 = c[0] - f0;
    const double  w1 = c[1] - f1;
    const int64_t lo0 = std::max<int64_t>(b0, 0);
    const int64_t hi0 = std::min<int64_t>(b0 + 1, m_Size[0] - 1);
    const float * row0 = m_Buffer + m_Size[0] * std::max<int64_t>(b1, 0);
    const float * row1 = m_Buffer + m_Size[0] * std::min<int64_t>(b1 + 1, m_Size[1] - 1);
    const double  c00 = static_cast<double>(row0[lo0]) + w0 * (static_cast<double>(row0[hi0]) - row0[lo0]);
    const double  c10 = static_cast<double>(row1[lo0]) + w0 * (static_cast<double>(row1[hi0]) - row1[lo0]);
    return c00 + w1 * (c10 - c00);
  }

  const float * m_Buffer{ nullptr };
  bool          m_Flat{ false };
  bool          m_Planar{ false };
  double        m_Matrix[3][3]{};
  double        m_Offset[3]{};
  int64_t       m_Size[3]{};
};

/** \class RegionForce
 * \brief The region force of DeformableMeshFilter: the outward speed of a
 * vertex from the intensity at its position, compared with the object's
 * intensity range.
 *
 * With I the (smoothed) intensity at the vertex, [L, U] the object's range
 * and w the transition width, the speed is
 * \f[
 *   v = \rho \, \mathrm{clamp}\left( \frac{\min(I - L,\; U - I)}{w}, -1, 1 \right)
 * \f]
 * (\f$ \rho \f$ the RegionWeight, mm per iteration): full inflation deep in
 * the object's range, full deflation where the intensity is w beyond it, and
 * zero on the iso-surfaces I = L and I = U, on which the surface therefore
 * settles whatever the number of iterations. A vertex outside the image
 * deflates at full speed.
 *
 * Estimate() derives the range from the interior of the initial surface:
 * intensities sampled on the segments from each vertex toward the vertices'
 * centroid (between 10 % and 60 % of the way); see Estimate() for the
 * bounds. A bright object on a dark background and a dark object on a bright
 * one are treated alike, on any intensity range; an initial surface that is
 * star-shaped around its centroid (a sphere inside the object) samples only
 * the object.
 * \ingroup ExplicitDeformableModel
 */
class RegionForce
{
public:
  /** Samples of the interior of the surface of coordinates x (3 per vertex):
   * fractions of the way from each vertex toward the centroid. */
  static std::vector<double>
  SampleInterior(const IntensitySampler & sampler, const double * x, size_t numberOfPoints)
  {
    double centroid[3] = { 0.0, 0.0, 0.0 };
    for (size_t i = 0; i < numberOfPoints; ++i)
    {
      for (unsigned int k = 0; k < 3; ++k)
      {
        centroid[k] += x[3 * i + k];
      }
    }
    for (unsigned int k = 0; k < 3; ++k)
    {
      centroid[k] /= static_cast<double>(numberOfPoints);
    }
    std::vector<double> samples;
    samples.reserve(6 * numberOfPoints);
    for (size_t i = 0; i < numberOfPoints; ++i)
    {
      for (double f = 0.1; f < 0.65; f += 0.1)
      {
        double p[3];
        for (unsigned int k = 0; k < 3; ++k)
        {
          p[k] = x[3 * i + k] + f * (centroid[k] - x[3 * i + k]);
        }
        const double value = sampler.Sample(p);
        if (std::isfinite(value))
        {
          samples.push_back(value);
        }
      }
    }
    return samples;
  }

  /** The median and the robust spread (1.4826 times the median absolute
   * deviation) of samples; false when there is none. */
  static bool
  Statistics(std::vector<double> samples, double & centre, double & spread)
  {
    if (samples.empty())
    {
      return false;
    }
    centre = Median(samples);
    for (double & value : samples)
    {
      value = std::abs(value - centre);
    }
    spread = 1.4826 * Median(samples);
    return std::isfinite(centre) && std::isfinite(spread);
  }

  /** Sets the object's model from its median m and robust spread s: the
   * object's class is [m - h, m + h] with h = k s, k the tolerance. When k s
   * is below a fifth of the image's range (high - low, its 98th and 2nd
   * percentiles), the object is piecewise constant (a binary or noiseless
   * image) and h = max(m - low, high - m) / 2 instead: the bound then lies
   * halfway between the object's intensity and the image's other extreme,
   * where the smoothed image crosses the object's edge. The range starts as
   * the class; AdaptToBackground() moves it. Width: max(s / 2, h / 8).
   * Returns false when the model is not finite. */
  bool
  SetModel(double centre, double spread, double tolerance, double low, double high)
  {
    double halfWidth = tolerance * spread;
    if (!(halfWidth >= 0.2 * (high - low)))
    {
      halfWidth = std::max(0.5 * (centre - low), 0.5 * (high - centre));
    }
    m_Centre = centre;
    m_DarkSamples = 0;
    m_BrightSamples = 0;
    m_ClassLower = centre - halfWidth;
    m_ClassUpper = centre + halfWidth;
    SetRange(m_ClassLower, m_ClassUpper, std::max(0.5 * spread, 0.125 * halfWidth));
    return std::isfinite(m_Lower) && std::isfinite(m_Upper) && m_Width > 0.0;
  }

  /** Statistics() and SetModel() of samples of the object. */
  bool
  Estimate(std::vector<double> samples, double tolerance, double low, double high)
  {
    double centre = 0.0;
    double spread = 0.0;
    return Statistics(std::move(samples), centre, spread) && SetModel(centre, spread, tolerance, low, high);
  }

  /** Moves the range's bounds from intensities sampled just outside the
   * surface. The samples below the object's class form the dark background,
   * those above it the bright background; a background with at least 5 % of
   * the samples (and 16) puts its bound halfway between the object's median
   * and its own median, the boundary of the two classes, where a blurred edge
   * between them has its steepest slope. A background with fewer samples
   * (the surface has not reached it) leaves its bound at the class's. */
  void
  AdaptToBackground(const std::vector<double> & samples)
  {
    std::vector<double> dark;
    std::vector<double> bright;
    for (const double value : samples)
    {
      if (value < m_ClassLower)
      {
        dark.push_back(value);
      }
      else if (value > m_ClassUpper)
      {
        bright.push_back(value);
      }
    }
    m_DarkSamples = dark.size();
    m_BrightSamples = bright.size();
    const size_t minimum = std::max<size_t>(16, samples.size() / 20);
    const double lower = dark.size() >= minimum ? 0.5 * (m_Centre + Median(dark)) : m_ClassLower;
    const double upper = bright.size() >= minimum ? 0.5 * (m_Centre + Median(bright)) : m_ClassUpper;
    SetRange(lower, upper, m_Width);
  }

  /** The q-quantiles (q in [0, 1]) of about a million voxels of image,
   * taken at a regular stride. */
  static std::vector<double>
  Quantiles(const Image<float, 3> * image, const std::vector<double> & q)
  {
    const float *      buffer = image->GetBufferPointer();
    const size_t       count = image->GetBufferedRegion().GetNumberOfPixels();
    const size_t       stride = std::max<size_t>(1, count / 1000000) | 1; // odd: no alignment with rows
    std::vector<float> values;
    if (stride == 1)
    {
      // A copy, and the non-finite values removed when a count (a loop the
      // compiler vectorises) finds any.
      values.assign(buffer, buffer + count);
      size_t nonFinite = 0;
      for (const float value : values)
      {
        nonFinite += !(std::abs(value) <= std::numeric_limits<float>::max());
      }
      if (nonFinite > 0)
      {
        values.erase(std::remove_if(values.begin(), values.end(), [](float v) { return !std::isfinite(v); }),
                     values.end());
      }
    }
    else
    {
      values.reserve(count / stride + 1);
      for (size_t i = 0; i < count; i += stride)
      {
        if (std::isfinite(buffer[i]))
        {
          values.push_back(buffer[i]);
        }
      }
    }
    std::vector<double> result;
    for (double fraction : q)
    {
      if (values.empty())
      {
        result.push_back(std::numeric_limits<double>::quiet_NaN());
        continue;
      }
      result.push_back(SelectRank(values, static_cast<size_t>(fraction * static_cast<double>(values.size() - 1))));
    }
    return result;
  }

  /** The q-quantile of the gradient magnitude of image (intensity per mm:
   * central differences, the image's spacing honoured) over about a million
   * of its inner voxels, taken at a regular stride. */
  static double
  GradientQuantile(const Image<float, 3> * image, double q)
  {
    const auto &  size = image->GetBufferedRegion().GetSize();
    const auto &  spacing = image->GetSpacing();
    const float * buffer = image->GetBufferPointer();
    const size_t  sx = 1;
    const size_t  sy = size[0];
    const size_t  sz = size[0] * size[1];
    const bool    flat = size[2] == 1;
    const size_t  count = image->GetBufferedRegion().GetNumberOfPixels();
    const size_t  stride = std::max<size_t>(1, count / 1000000) | 1;
    const double  dx = 2.0 * spacing[0];
    const double  dy = 2.0 * spacing[1];
    const double  dz = 2.0 * spacing[2];
    // Dividing by a power of two is multiplying by its inverse, exactly: the
    // same values without a division per voxel (a grid of 1 mm, 0.5 mm...).
    const auto powerOfTwo = [](double v) {
      int exponent = 0;
      return std::frexp(v, &exponent) == 0.5;
    };
    const bool   powersOfTwo = powerOfTwo(dx) && powerOfTwo(dy) && powerOfTwo(dz);
    const double inverseX = 1.0 / dx;
    const double inverseY = 1.0 / dy;
    const double inverseZ = 1.0 / dz;
    // The squared magnitudes are selected, and the root taken of the one
    // selected: the root, then the rounding to float, keep the order of the
    // values, so the result is that of selecting among the magnitudes (as
    // floats), without a square root per voxel.
    std::vector<double> values(count / stride + 1);
    size_t              n = 0;
    // byInverse: std::true_type multiplies by the inverses (power-of-two
    // spacings), std::false_type divides.
    const auto squaredMagnitude = [&](size_t offset, auto byInverse) {
      const auto derivative = [&](size_t step, double twoSpacings, double inverse) {
        const double difference = buffer[offset + step] - buffer[offset - step];
        if constexpr (decltype(byInverse)::value)
        {
          return difference * inverse;
        }
        else
        {
          return difference / twoSpacings;
        }
      };
      const double gx = derivative(sx, dx, inverseX);
      const double gy = derivative(sy, dy, inverseY);
      // One slice (a 2-D image embedded in 3-D): no z gradient.
      const double gz = flat ? 0.0 : derivative(sz, dz, inverseZ);
      return gx * gx + gy * gy + gz * gz;
    };
    if (stride == 1)
    {
      // Every inner voxel, row by row (loops the compiler vectorises).
      const size_t firstK = flat ? 0 : 1;
      const size_t endK = flat ? 1 : (size[2] > 1 ? size[2] - 1 : 0);
      const auto   fillRows = [&](auto byInverse) {
        for (size_t k = firstK; k < endK; ++k)
        {
          for (size_t j = 1; j + 1 < size[1]; ++j)
          {
            const size_t row = k * sz + j * sy;
            double *     out = values.data() + n;
            for (size_t i = 1; i + 1 < size[0]; ++i)
            {
              out[i - 1] = squaredMagnitude(row + i, byInverse);
            }
            n += size[0] > 2 ? size[0] - 2 : 0;
          }
        }
      };
      if (powersOfTwo)
      {
        fillRows(std::true_type{});
      }
      else
      {
        fillRows(std::false_type{});
      }
    }
    else
    {
      // The voxel (i, j, k) of offset, advanced with the offset (no division
      // per voxel: three of them cost more than the gradient).
      size_t i = 0;
      size_t j = 0;
      size_t k = 0;
      for (size_t offset = 0; offset < count; offset += stride)
      {
        if (offset > 0)
        {
          i += stride;
          while (i >= size[0])
          {
            i -= size[0];
            if (++j == size[1])
            {
              j = 0;
              ++k;
            }
          }
        }
        if (i == 0 || j == 0 || i + 1 >= size[0] || j + 1 >= size[1] || (!flat && (k == 0 || k + 1 >= size[2])))
        {
          continue;
        }
        values[n++] = squaredMagnitude(offset, std::false_type{});
      }
    }
    values.resize(n);
    // The non-finite values (squares: none is negative) removed when a count
    // (a loop the compiler vectorises) finds any.
    size_t nonFinite = 0;
    for (const double value : values)
    {
      nonFinite += !(value <= std::numeric_limits<double>::max());
    }
    if (nonFinite > 0)
    {
      values.erase(std::remove_if(values.begin(), values.end(), [](double v) { return !std::isfinite(v); }),
                   values.end());
    }
    if (values.empty())
    {
      return 0.0;
    }
    return static_cast<float>(
      std::sqrt(SelectRank(values, static_cast<size_t>(q * static_cast<double>(values.size() - 1)))));
  }

  /** The smallest transition width: speed changes by at most weight (mm per
   * iteration) over minimumWidth / gradient of intensity, so that a vertex
   * on an edge of that gradient does not step beyond the bound (the
   * linearised region term's gain per iteration is at most 1). */
  void
  SetMinimumWidth(double minimumWidth)
  {
    m_MinimumWidth = minimumWidth;
    SetRange(m_Lower, m_Upper, m_Width);
  }

  void
  SetRange(double lower, double upper, double width)
  {
    m_Lower = lower;
    m_Upper = upper;
    m_Width = std::max(width, m_MinimumWidth);
    m_InverseWidth = m_Width > 0.0 ? 1.0 / m_Width : 0.0;
  }

  double
  GetLower() const
  {
    return m_Lower;
  }
  double
  GetUpper() const
  {
    return m_Upper;
  }
  double
  GetWidth() const
  {
    return m_Width;
  }

  /** +1 when the object is brighter than its surroundings (the intensity
   * falls outward across its boundary), -1 when it is darker: the side of
   * the class that held more of the background's samples at the last
   * AdaptToBackground(), or, before any, the side of the image's intensity
   * range (its 2nd and 98th percentiles low and high) farther from the
   * object's median. */
  int
  Polarity(double low, double high) const
  {
    if (m_DarkSamples != m_BrightSamples)
    {
      return m_DarkSamples > m_BrightSamples ? 1 : -1;
    }
    return m_Centre - low >= high - m_Centre ? 1 : -1;
  }

  /** Outward speed in [-1, 1] for intensity value (NaN: outside the image,
   * -1). */
  double
  Speed(double value) const
  {
    if (!std::isfinite(value))
    {
      return -1.0;
    }
    const double margin = std::min(value - m_Lower, m_Upper - value) * m_InverseWidth;
    return std::max(-1.0, std::min(1.0, margin));
  }

private:
  static double
  Median(std::vector<double> & values)
  {
    const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), middle, values.end());
    return *middle;
  }

  double m_MinimumWidth{ 0.0 };
  size_t m_DarkSamples{ 0 };
  size_t m_BrightSamples{ 0 };
  double m_Centre{ 0.0 };
  double m_ClassLower{ 0.0 };
  double m_ClassUpper{ 0.0 };
  double m_Lower{ 0.0 };
  double m_Upper{ 0.0 };
  double m_Width{ 1.0 };
  double m_InverseWidth{ 1.0 };
};

} // namespace DeformableMeshFilterDetail
} // namespace itk

#endif
