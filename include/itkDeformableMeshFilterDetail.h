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
#ifndef itkDeformableMeshFilterDetail_h
#define itkDeformableMeshFilterDetail_h

#include <cmath>
#include <cstring>
#include <cstdint>
#include <type_traits>
#if defined(__AVX__)
#  include <immintrin.h>
#elif defined(__SSE2__) || defined(_M_X64) || (defined(_M_IX86_FP) && _M_IX86_FP >= 2)
#  include <emmintrin.h>
#endif

namespace itk
{
/** Four doubles handled as one value, for the step of DeformableMeshFilter: a
 * 3-D vector in lanes 0 to 2 and a lane 3 that the arithmetic carries along
 * and the results clear. With GCC and Clang it is a vector-extension type (one
 * AVX register, or two SSE registers); elsewhere a plain struct.
 * \ingroup ExplicitDeformableModel */
namespace DeformableMeshFilterDetail
{
#if defined(__GNUC__) || defined(__clang__)
#  define EDM_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#  define EDM_ALWAYS_INLINE inline
#endif

// The vector-extension type where it maps to one AVX register; with SSE2
// alone GCC moves its halves through memory, and a pair of SSE2 registers
// does better; elsewhere four plain doubles. EDM_VEC4_PORTABLE forces the
// plain version (to test it).
#if !defined(EDM_VEC4_PORTABLE) && (defined(__GNUC__) || defined(__clang__)) && defined(__AVX__)
#  define EDM_VECTOR_EXTENSIONS 1
#else
#  define EDM_VECTOR_EXTENSIONS 0
#endif
#if !defined(EDM_VEC4_PORTABLE) && !EDM_VECTOR_EXTENSIONS &&                                                           \
  (defined(__SSE2__) || defined(_M_X64) || (defined(_M_IX86_FP) && _M_IX86_FP >= 2))
#  define EDM_VEC4_SSE2 1
#else
#  define EDM_VEC4_SSE2 0
#endif

// The force sampler of DeformableMeshFilter computes the continuous indices,
// weights and corner offsets of four vertices at a time in AVX2 registers.
#if EDM_VECTOR_EXTENSIONS && defined(__AVX2__) && defined(__FMA__)
#  define EDM_AVX2_SAMPLER 1
#else
#  define EDM_AVX2_SAMPLER 0
#endif

#if EDM_VECTOR_EXTENSIONS
// Alignment 8: values are loaded from and stored to arrays of doubles at any
// offset, and objects holding them need no over-aligned allocation.
typedef double  Vec4 __attribute__((vector_size(32), aligned(8)));
typedef int64_t Vec4Mask __attribute__((vector_size(32), aligned(8)));

EDM_ALWAYS_INLINE Vec4
Splat(double s)
{
  return Vec4{ s, s, s, s };
}

/** (v1, v2, v0, v3): with it, a x b = Rotate(a * Rotate(b) - Rotate(a) * b). */
EDM_ALWAYS_INLINE Vec4
Rotate(const Vec4 & v)
{
#  if defined(__clang__)
  return __builtin_shufflevector(v, v, 1, 2, 0, 3);
#  else
  return __builtin_shuffle(v, Vec4Mask{ 1, 2, 0, 3 });
#  endif
}

/** (v0, v1, v2, 0). */
EDM_ALWAYS_INLINE Vec4
ClearLane3(const Vec4 & v)
{
#  if EDM_VECTOR_EXTENSIONS
  return _mm256_blend_pd(v, _mm256_setzero_pd(), 0x8);
#  elif defined(__clang__)
  return __builtin_shufflevector(v, Vec4{}, 0, 1, 2, 4);
#  else
  return __builtin_shuffle(v, Vec4{}, Vec4Mask{ 0, 1, 2, 4 });
#  endif
}

/** True when lanes 0 to 2 of a lie in [lower, upper). */
EDM_ALWAYS_INLINE bool
InsideBox(const Vec4 & a, const Vec4 & lower, const Vec4 & upper)
{
  const Vec4Mask inside = (a >= lower) & (a < upper);
  return (inside[0] & inside[1] & inside[2]) != 0;
}
#elif EDM_VEC4_SSE2
// Two SSE registers: (x, y) and (z, lane 3).
struct Vec4
{
  __m128d lo;
  __m128d hi;
  Vec4()
    : lo(_mm_setzero_pd())
    , hi(_mm_setzero_pd())
  {}
  Vec4(__m128d l, __m128d h)
    : lo(l)
    , hi(h)
  {}
  Vec4(double a, double b, double c, double d)
    : lo(_mm_set_pd(b, a))
    , hi(_mm_set_pd(d, c))
  {}
  double
  operator[](int k) const
  {
    const __m128d half = k < 2 ? lo : hi;
    return (k & 1) ? _mm_cvtsd_f64(_mm_unpackhi_pd(half, half)) : _mm_cvtsd_f64(half);
  }
};
#  define EDM_VEC4_OPERATOR(op, intrinsic)                                                                             \
    EDM_ALWAYS_INLINE Vec4 operator op(const Vec4 & a, const Vec4 & b)                                                 \
    {                                                                                                                  \
      return Vec4(intrinsic(a.lo, b.lo), intrinsic(a.hi, b.hi));                                                       \
    }                                                                                                                  \
    EDM_ALWAYS_INLINE Vec4 & operator op##=(Vec4 & a, const Vec4 & b)                                                  \
    {                                                                                                                  \
      return a = a op b;                                                                                               \
    }
EDM_VEC4_OPERATOR(+, _mm_add_pd)
EDM_VEC4_OPERATOR(-, _mm_sub_pd)
EDM_VEC4_OPERATOR(*, _mm_mul_pd)
#  undef EDM_VEC4_OPERATOR

EDM_ALWAYS_INLINE Vec4
Splat(double s)
{
  const __m128d v = _mm_set1_pd(s);
  return Vec4(v, v);
}

EDM_ALWAYS_INLINE Vec4
Rotate(const Vec4 & v)
{
  return Vec4(_mm_shuffle_pd(v.lo, v.hi, 1), _mm_shuffle_pd(v.lo, v.hi, 2));
}

EDM_ALWAYS_INLINE Vec4
ClearLane3(const Vec4 & v)
{
  return Vec4(v.lo, _mm_move_sd(_mm_setzero_pd(), v.hi));
}

EDM_ALWAYS_INLINE bool
InsideBox(const Vec4 & a, const Vec4 & lower, const Vec4 & upper)
{
  const __m128d low = _mm_and_pd(_mm_cmpge_pd(a.lo, lower.lo), _mm_cmplt_pd(a.lo, upper.lo));
  const __m128d high = _mm_and_pd(_mm_cmpge_pd(a.hi, lower.hi), _mm_cmplt_pd(a.hi, upper.hi));
  return _mm_movemask_pd(low) == 3 && (_mm_movemask_pd(high) & 1) == 1;
}
#else
struct Vec4
{
  double v[4];
  double &
  operator[](int k)
  {
    return v[k];
  }
  double
  operator[](int k) const
  {
    return v[k];
  }
};
#  define EDM_VEC4_OPERATOR(op)                                                                                        \
    inline Vec4 operator op(const Vec4 & a, const Vec4 & b)                                                            \
    {                                                                                                                  \
      return Vec4{ { a.v[0] op b.v[0], a.v[1] op b.v[1], a.v[2] op b.v[2], a.v[3] op b.v[3] } };                       \
    }                                                                                                                  \
    inline Vec4 & operator op##=(Vec4 & a, const Vec4 & b)                                                             \
    {                                                                                                                  \
      return a = a op b;                                                                                               \
    }
EDM_VEC4_OPERATOR(+)
EDM_VEC4_OPERATOR(-)
EDM_VEC4_OPERATOR(*)
#  undef EDM_VEC4_OPERATOR

EDM_ALWAYS_INLINE Vec4
Splat(double s)
{
  return Vec4{ { s, s, s, s } };
}

EDM_ALWAYS_INLINE Vec4
Rotate(const Vec4 & v)
{
  return Vec4{ { v.v[1], v.v[2], v.v[0], v.v[3] } };
}

EDM_ALWAYS_INLINE Vec4
ClearLane3(const Vec4 & v)
{
  return Vec4{ { v.v[0], v.v[1], v.v[2], 0.0 } };
}

EDM_ALWAYS_INLINE bool
InsideBox(const Vec4 & a, const Vec4 & lower, const Vec4 & upper)
{
  return a.v[0] >= lower.v[0] && a.v[0] < upper.v[0] && a.v[1] >= lower.v[1] && a.v[1] < upper.v[1] &&
         a.v[2] >= lower.v[2] && a.v[2] < upper.v[2];
}
#endif

/** Four doubles from p (p[3] must be readable). */
EDM_ALWAYS_INLINE Vec4
Load4(const double * p)
{
#if EDM_VECTOR_EXTENSIONS
  // A vector type aliases its element type; Vec4 is aligned as a double.
  return *reinterpret_cast<const Vec4 *>(p);
#elif EDM_VEC4_SSE2
  return Vec4(_mm_loadu_pd(p), _mm_loadu_pd(p + 2));
#else
  Vec4 v;
  std::memcpy(&v, p, sizeof(v));
  return v;
#endif
}

EDM_ALWAYS_INLINE void
Store4(double * p, const Vec4 & v)
{
#if EDM_VECTOR_EXTENSIONS
  *reinterpret_cast<Vec4 *>(p) = v;
#elif EDM_VEC4_SSE2
  _mm_storeu_pd(p, v.lo);
  _mm_storeu_pd(p + 2, v.hi);
#else
  std::memcpy(p, &v, sizeof(v));
#endif
}

EDM_ALWAYS_INLINE void
Store3(double * p, const Vec4 & v)
{
  p[0] = v[0];
  p[1] = v[1];
  p[2] = v[2];
}

/** Four floats from p, as doubles. */
EDM_ALWAYS_INLINE Vec4
LoadFloat4(const float * p)
{
#if EDM_VECTOR_EXTENSIONS
  return _mm256_cvtps_pd(_mm_loadu_ps(p));
#elif EDM_VEC4_SSE2
  const __m128 f = _mm_loadu_ps(p);
  return Vec4(_mm_cvtps_pd(f), _mm_cvtps_pd(_mm_movehl_ps(f, f)));
#else
  return Vec4{ p[0], p[1], p[2], p[3] };
#endif
}

/** The four lanes of v, rounded to floats, to p. */
EDM_ALWAYS_INLINE void
StoreFloat4(float * p, const Vec4 & v)
{
#if EDM_VECTOR_EXTENSIONS
  _mm_storeu_ps(p, _mm256_cvtpd_ps(v));
#elif EDM_VEC4_SSE2
  _mm_storeu_ps(p, _mm_movelh_ps(_mm_cvtpd_ps(v.lo), _mm_cvtpd_ps(v.hi)));
#else
  p[0] = static_cast<float>(v[0]);
  p[1] = static_cast<float>(v[1]);
  p[2] = static_cast<float>(v[2]);
  p[3] = static_cast<float>(v[3]);
#endif
}

/** 1 / n, from a table for the usual vertex valences. */
EDM_ALWAYS_INLINE double
InverseCount(uint32_t n)
{
  static constexpr double table[16] = { 0.0,     1.0,     1.0 / 2,  1.0 / 3,  1.0 / 4,  1.0 / 5,  1.0 / 6,  1.0 / 7,
                                        1.0 / 8, 1.0 / 9, 1.0 / 10, 1.0 / 11, 1.0 / 12, 1.0 / 13, 1.0 / 14, 1.0 / 15 };
  return n < 16 ? table[n] : 1.0 / static_cast<double>(n);
}

/** a . b in every lane; lane 3 of a * b must be 0. */
EDM_ALWAYS_INLINE Vec4
Dot4Splat(const Vec4 & a, const Vec4 & b)
{
  const Vec4 p = a * b;
#if EDM_VECTOR_EXTENSIONS
  const __m256d h = _mm256_hadd_pd(p, p); // (p0+p1, p0+p1, p2+p3, p2+p3)
  return _mm256_add_pd(h, _mm256_permute2f128_pd(h, h, 1));
#else
  return Splat(p[0] + p[1] + p[2] + p[3]);
#endif
}

/** Lanes 0 to 2 of a . b. */
EDM_ALWAYS_INLINE double
Dot3(const Vec4 & a, const Vec4 & b)
{
  const Vec4 p = a * b;
  return p[0] + p[1] + p[2];
}

/** (a . a, b . b, c . c, 0); lane 3 of a, b and c must be 0. */
EDM_ALWAYS_INLINE Vec4
SquaredLengths(const Vec4 & a, const Vec4 & b, const Vec4 & c)
{
#if EDM_VECTOR_EXTENSIONS
  const __m256d ab = _mm256_hadd_pd(a * a, b * b);               // (a0+a1, b0+b1, a2+a3, b2+b3)
  const __m256d c0 = _mm256_hadd_pd(c * c, _mm256_setzero_pd()); // (c0+c1, 0, c2+c3, 0)
  return _mm256_add_pd(_mm256_permute2f128_pd(ab, c0, 0x20), _mm256_permute2f128_pd(ab, c0, 0x31));
#else
  return Vec4{ Dot3(a, a), Dot3(b, b), Dot3(c, c), 0.0 };
#endif
}

/** Square roots of lanes 0 to 2 of squares into *a, *b and *c, in single
 * precision. The roots are taken in double precision: squares of small
 * lengths are subnormal in single precision, whose square roots cost a
 * hundred cycles or more. */
EDM_ALWAYS_INLINE void
SqrtStore3(const Vec4 & squares, float * a, float * b, float * c)
{
#if EDM_VECTOR_EXTENSIONS
  const __m128 r = _mm256_cvtpd_ps(_mm256_sqrt_pd(squares));
  _mm_store_ss(a, r);
  *b = _mm_cvtss_f32(_mm_movehdup_ps(r));
  *c = _mm_cvtss_f32(_mm_movehl_ps(r, r));
#else
  *a = static_cast<float>(std::sqrt(squares[0]));
  *b = static_cast<float>(std::sqrt(squares[1]));
  *c = static_cast<float>(std::sqrt(squares[2]));
#endif
}

/** The 3 components of a force pixel as lanes 0 to 2; lane 3 is whatever
 * follows them in memory when Padded (the caller guarantees it is readable)
 * and 0 otherwise. */
template <typename TPixel, bool Padded>
struct PixelLoader
{
  static Vec4
  Load(const TPixel & p)
  {
    return Vec4{ static_cast<double>(p[0]), static_cast<double>(p[1]), static_cast<double>(p[2]), 0.0 };
  }
};

template <typename TPixel>
struct PixelLoader<TPixel, true>
{
  static Vec4
  Load(const TPixel & p)
  {
    using ValueType = typename TPixel::ValueType;
    if (std::is_same<ValueType, double>::value && sizeof(TPixel) == 3 * sizeof(double))
    {
      return Load4(reinterpret_cast<const double *>(&p));
    }
#if EDM_VECTOR_EXTENSIONS
    if (std::is_same<ValueType, float>::value && sizeof(TPixel) == 3 * sizeof(float))
    {
#  if EDM_VECTOR_EXTENSIONS
      return _mm256_cvtps_pd(_mm_loadu_ps(reinterpret_cast<const float *>(&p)));
#  else
      typedef float Float4 __attribute__((vector_size(16), aligned(4)));
      return __builtin_convertvector(*reinterpret_cast<const Float4 *>(&p), Vec4);
#  endif
    }
#elif EDM_VEC4_SSE2
    if (std::is_same<ValueType, float>::value && sizeof(TPixel) == 3 * sizeof(float))
    {
      const __m128 f = _mm_loadu_ps(reinterpret_cast<const float *>(&p));
      return Vec4(_mm_cvtps_pd(f), _mm_cvtps_pd(_mm_movehl_ps(f, f)));
    }
#endif
    return PixelLoader<TPixel, false>::Load(p);
  }
};

/** Vertices in a chunk of the step: the forces of a run of this many are
 * sampled together, the normals of a chunk are scaled together, and on meshes
 * of mixed valences the vertices of a chunk are ordered by valence. */
constexpr std::size_t ChunkSize = 32;

/** n / |n| times sign (lane 3 of n must be 0); 0 when n is 0. */
EDM_ALWAYS_INLINE Vec4
UnitVector(const Vec4 & n, double sign)
{
  const double squaredLength = Dot3(n, n);
  return squaredLength > 0.0 ? n * Splat(sign / std::sqrt(squaredLength)) : Vec4{};
}

/** Calls f(std::true_type()) or f(std::false_type()) as \a value: a run-time
 * flag turned into a template argument. */
template <typename TFunction>
EDM_ALWAYS_INLINE void
WithConstant(bool value, TFunction && f)
{
  if (value)
  {
    f(std::true_type());
  }
  else
  {
    f(std::false_type());
  }
}

/** For a count of 4 to 8 (the usual valences), calls
 * f(std::integral_constant<unsigned int, count>()) and returns true; returns
 * false for other counts. The step has straight-line code for these. */
template <typename TFunction>
EDM_ALWAYS_INLINE bool
WithUsualValence(uint32_t count, TFunction && f)
{
  switch (count)
  {
    case 4:
      f(std::integral_constant<unsigned int, 4>());
      return true;
    case 5:
      f(std::integral_constant<unsigned int, 5>());
      return true;
    case 6:
      f(std::integral_constant<unsigned int, 6>());
      return true;
    case 7:
      f(std::integral_constant<unsigned int, 7>());
      return true;
    case 8:
      f(std::integral_constant<unsigned int, 8>());
      return true;
    default:
      return false;
  }
}

/** Sum of the 4-float vectors field[4 j] for the K indices j of \a indices,
 * in two interleaved partial sums. K >= 2. */
template <unsigned int K, typename TIndex>
EDM_ALWAYS_INLINE Vec4
GatherSum(const float * field, const TIndex * indices)
{
  Vec4 sum[2] = { LoadFloat4(field + 4 * static_cast<std::size_t>(indices[0])),
                  LoadFloat4(field + 4 * static_cast<std::size_t>(indices[1])) };
#if defined(__GNUC__) && !defined(__clang__)
#  pragma GCC unroll 8
#endif
  for (unsigned int k = 2; k < K; ++k)
  {
    sum[k % 2] += LoadFloat4(field + 4 * static_cast<std::size_t>(indices[k]));
  }
  return sum[0] + sum[1];
}

/** Trilinear interpolation of the corners p000, p100, p010, p110, p001, p101,
 * p011, p111 (x fastest) with weights (wx, wy, wz) in [0, 1]. */
EDM_ALWAYS_INLINE Vec4
Trilinear(const Vec4 (&p)[8], double wx, double wy, double wz)
{
  const Vec4 vx = Splat(wx);
  const Vec4 a00 = p[0] + vx * (p[1] - p[0]);
  const Vec4 a10 = p[2] + vx * (p[3] - p[2]);
  const Vec4 a01 = p[4] + vx * (p[5] - p[4]);
  const Vec4 a11 = p[6] + vx * (p[7] - p[6]);
  const Vec4 vy = Splat(wy);
  const Vec4 near = a00 + vy * (a10 - a00);
  const Vec4 far = a01 + vy * (a11 - a01);
  return ClearLane3(near + Splat(wz) * (far - near));
}
} // namespace DeformableMeshFilterDetail
} // namespace itk

#endif
