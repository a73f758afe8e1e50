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

// No include guard: itkDeformableMeshFilterKernels.h includes this file once
// per instruction set, inside a namespace of that instruction set, with
// EDM_KERNEL_ISA set to EDM_ISA_AVX2, EDM_ISA_SSE2 or EDM_ISA_PORTABLE. Not a
// header of its own.
//
// Vec4: four doubles handled as one value, a 3-D vector in lanes 0 to 2 and a
// lane 3 that the arithmetic carries along and the results clear. With AVX2 a
// vector-extension type (one register); with SSE2 alone a pair of registers
// (GCC would move the halves of a vector-extension type through memory);
// otherwise four plain doubles.

#if EDM_KERNEL_ISA == EDM_ISA_AVX2
// Alignment 8: values are loaded from and stored to arrays of doubles at any
// offset.
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
  return _mm256_blend_pd(v, _mm256_setzero_pd(), 0x8);
}

/** True when lanes 0 to 2 of a lie in [lower, upper). */
EDM_ALWAYS_INLINE bool
InsideBox(const Vec4 & a, const Vec4 & lower, const Vec4 & upper)
{
  const Vec4Mask inside = (a >= lower) & (a < upper);
  return (inside[0] & inside[1] & inside[2]) != 0;
}

/** Four doubles from p (p[3] must be readable). */
EDM_ALWAYS_INLINE Vec4
Load4(const double * p)
{
  // A vector type aliases its element type; Vec4 is aligned as a double.
  return *reinterpret_cast<const Vec4 *>(p);
}

EDM_ALWAYS_INLINE void
Store4(double * p, const Vec4 & v)
{
  *reinterpret_cast<Vec4 *>(p) = v;
}

/** Four floats from p, as doubles. */
EDM_ALWAYS_INLINE Vec4
LoadFloat4(const float * p)
{
  return _mm256_cvtps_pd(_mm_loadu_ps(p));
}

/** The four lanes of v, rounded to floats, to p. */
EDM_ALWAYS_INLINE void
StoreFloat4(float * p, const Vec4 & v)
{
  _mm_storeu_ps(p, _mm256_cvtpd_ps(v));
}

/** a . b in every lane; lane 3 of a * b must be 0. */
EDM_ALWAYS_INLINE Vec4
Dot4Splat(const Vec4 & a, const Vec4 & b)
{
  const Vec4    p = a * b;
  const __m256d h = _mm256_hadd_pd(p, p); // (p0+p1, p0+p1, p2+p3, p2+p3)
  return _mm256_add_pd(h, _mm256_permute2f128_pd(h, h, 1));
}

/** (a . a, b . b, c . c, 0); lane 3 of a, b and c must be 0. */
EDM_ALWAYS_INLINE Vec4
SquaredLengths(const Vec4 & a, const Vec4 & b, const Vec4 & c)
{
  const __m256d ab = _mm256_hadd_pd(a * a, b * b);               // (a0+a1, b0+b1, a2+a3, b2+b3)
  const __m256d c0 = _mm256_hadd_pd(c * c, _mm256_setzero_pd()); // (c0+c1, 0, c2+c3, 0)
  return _mm256_add_pd(_mm256_permute2f128_pd(ab, c0, 0x20), _mm256_permute2f128_pd(ab, c0, 0x31));
}

/** Square roots of lanes 0 to 2 of squares into *a, *b and *c, in single
 * precision. The roots are taken in double precision: squares of small
 * lengths are subnormal in single precision, whose square roots cost a
 * hundred cycles or more. */
EDM_ALWAYS_INLINE void
SqrtStore3(const Vec4 & squares, float * a, float * b, float * c)
{
  const __m128 r = _mm256_cvtpd_ps(_mm256_sqrt_pd(squares));
  _mm_store_ss(a, r);
  *b = _mm_cvtss_f32(_mm_movehdup_ps(r));
  *c = _mm_cvtss_f32(_mm_movehl_ps(r, r));
}

/** Three floats and the one after them (readable), as doubles. */
EDM_ALWAYS_INLINE Vec4
LoadPaddedFloat3(const float * p)
{
  return _mm256_cvtps_pd(_mm_loadu_ps(p));
}

#elif EDM_KERNEL_ISA == EDM_ISA_SSE2
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

EDM_ALWAYS_INLINE Vec4
operator+(const Vec4 & a, const Vec4 & b)
{
  return Vec4(_mm_add_pd(a.lo, b.lo), _mm_add_pd(a.hi, b.hi));
}
EDM_ALWAYS_INLINE Vec4
operator-(const Vec4 & a, const Vec4 & b)
{
  return Vec4(_mm_sub_pd(a.lo, b.lo), _mm_sub_pd(a.hi, b.hi));
}
EDM_ALWAYS_INLINE Vec4
operator*(const Vec4 & a, const Vec4 & b)
{
  return Vec4(_mm_mul_pd(a.lo, b.lo), _mm_mul_pd(a.hi, b.hi));
}

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

EDM_ALWAYS_INLINE Vec4
Load4(const double * p)
{
  return Vec4(_mm_loadu_pd(p), _mm_loadu_pd(p + 2));
}

EDM_ALWAYS_INLINE void
Store4(double * p, const Vec4 & v)
{
  _mm_storeu_pd(p, v.lo);
  _mm_storeu_pd(p + 2, v.hi);
}

EDM_ALWAYS_INLINE Vec4
LoadFloat4(const float * p)
{
  const __m128 f = _mm_loadu_ps(p);
  return Vec4(_mm_cvtps_pd(f), _mm_cvtps_pd(_mm_movehl_ps(f, f)));
}

EDM_ALWAYS_INLINE void
StoreFloat4(float * p, const Vec4 & v)
{
  _mm_storeu_ps(p, _mm_movelh_ps(_mm_cvtpd_ps(v.lo), _mm_cvtpd_ps(v.hi)));
}

EDM_ALWAYS_INLINE Vec4
LoadPaddedFloat3(const float * p)
{
  return LoadFloat4(p);
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

inline Vec4
operator+(const Vec4 & a, const Vec4 & b)
{
  return Vec4{ { a.v[0] + b.v[0], a.v[1] + b.v[1], a.v[2] + b.v[2], a.v[3] + b.v[3] } };
}
inline Vec4
operator-(const Vec4 & a, const Vec4 & b)
{
  return Vec4{ { a.v[0] - b.v[0], a.v[1] - b.v[1], a.v[2] - b.v[2], a.v[3] - b.v[3] } };
}
inline Vec4
operator*(const Vec4 & a, const Vec4 & b)
{
  return Vec4{ { a.v[0] * b.v[0], a.v[1] * b.v[1], a.v[2] * b.v[2], a.v[3] * b.v[3] } };
}

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

EDM_ALWAYS_INLINE Vec4
Load4(const double * p)
{
  Vec4 v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}

EDM_ALWAYS_INLINE void
Store4(double * p, const Vec4 & v)
{
  std::memcpy(p, &v, sizeof(v));
}

EDM_ALWAYS_INLINE Vec4
LoadFloat4(const float * p)
{
  return Vec4{ { p[0], p[1], p[2], p[3] } };
}

EDM_ALWAYS_INLINE void
StoreFloat4(float * p, const Vec4 & v)
{
  p[0] = static_cast<float>(v[0]);
  p[1] = static_cast<float>(v[1]);
  p[2] = static_cast<float>(v[2]);
  p[3] = static_cast<float>(v[3]);
}

EDM_ALWAYS_INLINE Vec4
LoadPaddedFloat3(const float * p)
{
  return Vec4{ { p[0], p[1], p[2], 0.0 } };
}
#endif

#if EDM_KERNEL_ISA != EDM_ISA_AVX2
EDM_ALWAYS_INLINE Vec4 &
operator+=(Vec4 & a, const Vec4 & b)
{
  return a = a + b;
}

EDM_ALWAYS_INLINE Vec4 &
operator*=(Vec4 & a, const Vec4 & b)
{
  return a = a * b;
}
#endif

EDM_ALWAYS_INLINE void
Store3(double * p, const Vec4 & v)
{
  p[0] = v[0];
  p[1] = v[1];
  p[2] = v[2];
}

/** Lanes 0 to 2 of a . b. */
EDM_ALWAYS_INLINE double
Dot3(const Vec4 & a, const Vec4 & b)
{
  const Vec4 p = a * b;
  return p[0] + p[1] + p[2];
}

#if EDM_KERNEL_ISA != EDM_ISA_AVX2
EDM_ALWAYS_INLINE Vec4
Dot4Splat(const Vec4 & a, const Vec4 & b)
{
  const Vec4 p = a * b;
  return Splat(p[0] + p[1] + p[2] + p[3]);
}

EDM_ALWAYS_INLINE Vec4
SquaredLengths(const Vec4 & a, const Vec4 & b, const Vec4 & c)
{
  return Vec4{ Dot3(a, a), Dot3(b, b), Dot3(c, c), 0.0 };
}

EDM_ALWAYS_INLINE void
SqrtStore3(const Vec4 & squares, float * a, float * b, float * c)
{
  *a = static_cast<float>(std::sqrt(squares[0]));
  *b = static_cast<float>(std::sqrt(squares[1]));
  *c = static_cast<float>(std::sqrt(squares[2]));
}
#endif
