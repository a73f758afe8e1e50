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
// per instruction set, after itkDeformableMeshFilterVec4.h, inside the
// namespace of that instruction set. Not a header of its own.
//
// The step of DeformableMeshFilter on flat arrays: the force sampler, the
// ring geometry (umbrella vector and normal), the geometry pass and the step
// of a work block. The update rule they implement is
// DeformableMeshUpdateRule (itkDeformableMeshUpdateRule.h), in scalar form;
// a test holds this code against it.

/** 1 / n, from a table for the usual vertex valences. */
EDM_ALWAYS_INLINE double
InverseCount(uint32_t n)
{
  static constexpr double table[16] = { 0.0,     1.0,     1.0 / 2,  1.0 / 3,  1.0 / 4,  1.0 / 5,  1.0 / 6,  1.0 / 7,
                                        1.0 / 8, 1.0 / 9, 1.0 / 10, 1.0 / 11, 1.0 / 12, 1.0 / 13, 1.0 / 14, 1.0 / 15 };
  return n < 16 ? table[n] : 1.0 / static_cast<double>(n);
}

/** n / |n| times sign (lane 3 of n must be 0); 0 when n is 0. */
EDM_ALWAYS_INLINE Vec4
UnitVector(const Vec4 & n, double sign)
{
  const double squaredLength = Dot3(n, n);
  return squaredLength > 0.0 ? n * Splat(sign / std::sqrt(squaredLength)) : Vec4{};
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
template <unsigned int K>
EDM_ALWAYS_INLINE Vec4
GatherSum(const float * field, const uint32_t * indices)
{
  Vec4 sum[2] = { LoadFloat4(field + 4 * static_cast<std::size_t>(indices[0])),
                  LoadFloat4(field + 4 * static_cast<std::size_t>(indices[1])) };
  EDM_UNROLL_8
  for (unsigned int k = 2; k < K; ++k)
  {
    sum[k % 2] += LoadFloat4(field + 4 * static_cast<std::size_t>(indices[k]));
  }
  return sum[0] + sum[1];
}

// ---------------------------------------------------------------------------
// Force sampler

/** The 3 components of a force pixel as lanes 0 to 2; lane 3 is whatever
 * follows them in memory when Padded (the caller guarantees it is readable)
 * and 0 otherwise. */
template <typename TPixel, bool Padded>
EDM_ALWAYS_INLINE Vec4
LoadPixel(const TPixel & p)
{
  using ValueType = typename TPixel::ValueType;
  if (Padded && std::is_same<ValueType, double>::value && sizeof(TPixel) == 3 * sizeof(double))
  {
    return Load4(reinterpret_cast<const double *>(&p));
  }
  if (Padded && std::is_same<ValueType, float>::value && sizeof(TPixel) == 3 * sizeof(float))
  {
    return LoadPaddedFloat3(reinterpret_cast<const float *>(&p));
  }
  return Vec4{ static_cast<double>(p[0]), static_cast<double>(p[1]), static_cast<double>(p[2]), 0.0 };
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

/** A ForceSampler's vectors in registers. */
struct SamplerVectors
{
  Vec4 columns[3];
  Vec4 offset;
  Vec4 lower;
  Vec4 upper;

  template <typename TPixel>
  EDM_ALWAYS_INLINE explicit SamplerVectors(const ForceSampler<TPixel> & s)
  {
    for (unsigned int c = 0; c < 3; ++c)
    {
      columns[c] = Vec4{ s.columns[c][0], s.columns[c][1], s.columns[c][2], 0.0 };
    }
    offset = Vec4{ s.offset[0], s.offset[1], s.offset[2], 0.0 };
    lower = Vec4{ s.lower[0], s.lower[1], s.lower[2], 0.0 };
    upper = Vec4{ s.upper[0], s.upper[1], s.upper[2], 0.0 };
  }
};

/** Trilinear sample of the force image at the physical point xi (lane 3
 * ignored); zero outside the image. Lane 3 of the result is 0. */
template <typename TPixel>
EDM_ALWAYS_INLINE Vec4
SampleForce(const ForceSampler<TPixel> & sampler, const SamplerVectors & v, const Vec4 & xi)
{
  const Vec4 c = v.columns[0] * Splat(xi[0]) + v.columns[1] * Splat(xi[1]) + v.columns[2] * Splat(xi[2]) - v.offset;
  if (!InsideBox(c, v.lower, v.upper))
  {
    return Vec4{};
  }
  // c >= -0.5, so truncating c + 1 gives floor(c) + 1.
  const auto    fx = static_cast<int64_t>(c[0] + 1.0) - 1;
  const auto    fy = static_cast<int64_t>(c[1] + 1.0) - 1;
  const auto    fz = static_cast<int64_t>(c[2] + 1.0) - 1;
  const int64_t x0 = std::max<int64_t>(fx, 0);
  const int64_t x1 = std::min<int64_t>(fx + 1, sampler.last[0]);
  const int64_t y0 = std::max<int64_t>(fy, 0) * sampler.strideY;
  const int64_t y1 = std::min<int64_t>(fy + 1, sampler.last[1]) * sampler.strideY;
  const int64_t z0 = std::max<int64_t>(fz, 0) * sampler.strideZ;
  const int64_t z1 = std::min<int64_t>(fz + 1, sampler.last[2]) * sampler.strideZ;
  const int64_t corners[8] = { z0 + y0 + x0, z0 + y0 + x1, z0 + y1 + x0, z0 + y1 + x1,
                               z1 + y0 + x0, z1 + y0 + x1, z1 + y1 + x0, z1 + y1 + x1 };
  Vec4          p[8];
  // A padded load reads past the pixel: not at the last pixel of the buffer.
  if (corners[7] < sampler.lastPixel)
  {
    for (unsigned int k = 0; k < 8; ++k)
    {
      p[k] = LoadPixel<TPixel, true>(sampler.buffer[corners[k]]);
    }
  }
  else
  {
    for (unsigned int k = 0; k < 8; ++k)
    {
      p[k] = LoadPixel<TPixel, false>(sampler.buffer[corners[k]]);
    }
  }
  return Trilinear(p, c[0] - static_cast<double>(fx), c[1] - static_cast<double>(fy), c[2] - static_cast<double>(fz));
}

/** SampleForce() times \a scale at vertices [begin, end) (coordinates \a x,
 * 3 per vertex), into forces[0, end - begin); at most one chunk. */
template <typename TPixel>
EDM_ALWAYS_INLINE void
SampleForces(const ForceSampler<TPixel> & sampler,
             const SamplerVectors &       v,
             const double *               x,
             SizeValueType                begin,
             SizeValueType                end,
             double                       scale,
             Vec4 *                       forces)
{
#if EDM_KERNEL_ISA == EDM_ISA_AVX2
  if (sampler.smallBuffer)
  {
    // Four vertices at a time: their coordinates as one register per axis,
    // then continuous indices, inside test, weights and the byte offsets of
    // the eight corners (clamped at the border) in the lanes of registers;
    // the corners are then loaded and blended vertex by vertex.
    const char *        bytes = reinterpret_cast<const char *>(sampler.buffer);
    const __m128i       lastBytes = _mm_set1_epi32(static_cast<int32_t>(sampler.lastPixel * sizeof(TPixel)));
    alignas(32) int32_t corners[8][ChunkSize];
    alignas(32) double  weights[3][ChunkSize];
    uint32_t            insideBits = 0;
    uint32_t            paddedBits = 0;
    double              tail[12];
    for (SizeValueType j = begin; j < end; j += 4)
    {
      // The last group of a chunk may be short: its coordinates are copied,
      // the missing vertices repeating the last one.
      const SizeValueType count = std::min<SizeValueType>(4, end - j);
      const double *      xj = x + 3 * j;
      if (count < 4)
      {
        for (SizeValueType k = 0; k < 12; ++k)
        {
          tail[k] = xj[std::min(k, 3 * count - 3 + k % 3)];
        }
        xj = tail;
      }
      const __m256d a = _mm256_loadu_pd(xj);     // x0 y0 z0 x1
      const __m256d b = _mm256_loadu_pd(xj + 4); // y1 z1 x2 y2
      const __m256d c = _mm256_loadu_pd(xj + 8); // z2 x3 y3 z3
      const __m256d axis[3] = { _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(a, c, 0x2), b, 0x4), 0x6C),
                                _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(a, b, 0x9), c, 0x4), 0xB1),
                                _mm256_permute4x64_pd(_mm256_blend_pd(_mm256_blend_pd(a, b, 0x2), c, 0x9), 0xC6) };
      int           inside = 0xF;
      __m128i       low[3];
      __m128i       high[3];
      for (unsigned int k = 0; k < 3; ++k)
      {
        // The products and sums in the order GCC gives SampleForce() with FMA:
        // both give the same bits (checked on 300-step runs).
        __m256d ck = _mm256_mul_pd(_mm256_set1_pd(sampler.columns[1][k]), axis[1]);
        ck = _mm256_fmadd_pd(_mm256_set1_pd(sampler.columns[0][k]), axis[0], ck);
        ck = _mm256_fmadd_pd(_mm256_set1_pd(sampler.columns[2][k]), axis[2], ck);
        ck = _mm256_sub_pd(ck, _mm256_set1_pd(sampler.offset[k]));
        inside &= _mm256_movemask_pd(_mm256_and_pd(_mm256_cmp_pd(ck, _mm256_set1_pd(sampler.lower[k]), _CMP_GE_OQ),
                                                   _mm256_cmp_pd(ck, _mm256_set1_pd(sampler.upper[k]), _CMP_LT_OQ)));
        const __m256d f = _mm256_floor_pd(ck);
        const __m256d stride = _mm256_set1_pd(sampler.byteStrides[k]);
        _mm256_store_pd(weights[k] + (j - begin), _mm256_sub_pd(ck, f));
        low[k] = _mm256_cvttpd_epi32(_mm256_mul_pd(_mm256_max_pd(f, _mm256_setzero_pd()), stride));
        high[k] = _mm256_cvttpd_epi32(_mm256_mul_pd(
          _mm256_min_pd(_mm256_add_pd(f, _mm256_set1_pd(1.0)), _mm256_set1_pd(static_cast<double>(sampler.last[k]))),
          stride));
      }
      const __m128i yz[4] = { _mm_add_epi32(low[1], low[2]),
                              _mm_add_epi32(high[1], low[2]),
                              _mm_add_epi32(low[1], high[2]),
                              _mm_add_epi32(high[1], high[2]) };
      for (unsigned int k = 0; k < 4; ++k)
      {
        _mm_store_si128(reinterpret_cast<__m128i *>(corners[2 * k] + (j - begin)), _mm_add_epi32(yz[k], low[0]));
        _mm_store_si128(reinterpret_cast<__m128i *>(corners[2 * k + 1] + (j - begin)), _mm_add_epi32(yz[k], high[0]));
      }
      // A padded load reads past the pixel: not at the last pixel of the buffer.
      const int padded = _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpgt_epi32(lastBytes, _mm_add_epi32(yz[3], high[0]))));
      insideBits |= static_cast<uint32_t>(inside) << (j - begin);
      paddedBits |= static_cast<uint32_t>(padded) << (j - begin);
    }
    // Then the loads and blends, which depend on nothing but the offsets
    // above: the loads of several vertices are in flight at once.
    for (SizeValueType l = 0; l < end - begin; ++l)
    {
      Vec4 force{};
      if (insideBits & (uint32_t{ 1 } << l))
      {
        Vec4 p[8];
        if (paddedBits & (uint32_t{ 1 } << l))
        {
          for (unsigned int k = 0; k < 8; ++k)
          {
            p[k] = LoadPixel<TPixel, true>(*reinterpret_cast<const TPixel *>(bytes + corners[k][l]));
          }
        }
        else
        {
          for (unsigned int k = 0; k < 8; ++k)
          {
            p[k] = LoadPixel<TPixel, false>(*reinterpret_cast<const TPixel *>(bytes + corners[k][l]));
          }
        }
        force = Splat(scale) * Trilinear(p, weights[0][l], weights[1][l], weights[2][l]);
      }
      forces[l] = force;
    }
    return;
  }
#endif
  for (SizeValueType j = begin; j < end; ++j)
  {
    forces[j - begin] = Splat(scale) * SampleForce(sampler, v, Load4(x + 3 * j));
  }
}

// ---------------------------------------------------------------------------
// Ring geometry

/** Umbrella vector u and, when NeedNormal, the area-weighted normal n of a
 * ClosedRing vertex of K neighbours: as in ComputeGeometry(), with the sums
 * split in two (even and odd terms) to shorten their dependency chains. */
template <unsigned int K, bool NeedNormal>
EDM_ALWAYS_INLINE void
ClosedRingGeometry(const double * x, const uint32_t * ring, const Vec4 & xi, Vec4 & u, Vec4 & n)
{
  Vec4 d[K];
  Vec4 r[K];
  EDM_UNROLL_8
  for (unsigned int k = 0; k < K; ++k)
  {
    d[k] = Load4(x + 3 * static_cast<SizeValueType>(ring[k])) - xi;
    r[k] = Rotate(d[k]);
  }
  Vec4 sum[2] = { d[0], d[1] };
  EDM_UNROLL_8
  for (unsigned int k = 2; k < K; ++k)
  {
    sum[k % 2] += d[k];
  }
  u = ClearLane3((sum[0] + sum[1]) * Splat(1.0 / static_cast<double>(K)));
  if (NeedNormal)
  {
    Vec4 twisted[2] = { d[0] * r[1] - r[0] * d[1], d[1] * r[2] - r[1] * d[2] };
    EDM_UNROLL_8
    for (unsigned int k = 2; k < K; ++k)
    {
      twisted[k % 2] += d[k] * r[(k + 1) % K] - r[k] * d[(k + 1) % K];
    }
    n = ClearLane3(Rotate(twisted[0] + twisted[1]));
  }
}

/** ComputeGeometry() of a GeneralVertex: the neighbours in any order, the
 * normal from the vertex's triangles kept apart. */
inline void
GeneralGeometry(const MeshTables & mesh, const double * x, SizeValueType i, Vec4 & u, Vec4 & n)
{
  const double * xi = x + 3 * i;
  double         s[3] = { 0.0, 0.0, 0.0 };
  const uint32_t begin = mesh.neighbourOffsets[i];
  const uint32_t end = mesh.neighbourOffsets[i + 1];
  for (uint32_t k = begin; k < end; ++k)
  {
    const double * y = x + 3 * static_cast<SizeValueType>(mesh.neighbours[k]);
    s[0] += y[0] - xi[0];
    s[1] += y[1] - xi[1];
    s[2] += y[2] - xi[2];
  }
  const double inverseCount = end > begin ? 1.0 / static_cast<double>(end - begin) : 0.0;
  u = Vec4{ s[0] * inverseCount, s[1] * inverseCount, s[2] * inverseCount, 0.0 };

  const auto rank = static_cast<SizeValueType>(
    std::lower_bound(mesh.generalVertices, mesh.generalVertices + mesh.numberOfGeneral, static_cast<uint32_t>(i)) -
    mesh.generalVertices);
  double normal[3] = { 0.0, 0.0, 0.0 };
  for (uint32_t k = mesh.generalPairOffsets[rank]; k < mesh.generalPairOffsets[rank + 1]; ++k)
  {
    const double * b = x + 3 * static_cast<SizeValueType>(mesh.generalPairs[2 * k]);
    const double * c = x + 3 * static_cast<SizeValueType>(mesh.generalPairs[2 * k + 1]);
    const double   e[3] = { b[0] - xi[0], b[1] - xi[1], b[2] - xi[2] };
    const double   f[3] = { c[0] - xi[0], c[1] - xi[1], c[2] - xi[2] };
    normal[0] += e[1] * f[2] - e[2] * f[1];
    normal[1] += e[2] * f[0] - e[0] * f[2];
    normal[2] += e[0] * f[1] - e[1] * f[0];
  }
  n = Vec4{ normal[0], normal[1], normal[2], 0.0 };
}

/** Umbrella vector u (centroid of the neighbours minus the vertex) and, when
 * NeedNormal, the area-weighted normal n of vertex i: the sum of the cross
 * products of its triangles' edges from the vertex, neither unit nor oriented
 * (UnitVector() with the orientation sign makes it the outward unit normal).
 * Lane 3 of both is 0. */
template <bool NeedNormal>
EDM_ALWAYS_INLINE void
ComputeGeometry(const MeshTables & mesh, const double * x, SizeValueType i, Vec4 & u, Vec4 & n)
{
  const uint8_t kind = mesh.ringKinds[i];
  if (kind == GeneralVertex)
  {
    // Through temporaries: u and n stay in registers on the other paths.
    Vec4 generalU;
    Vec4 generalN;
    GeneralGeometry(mesh, x, i, generalU, generalN);
    u = generalU;
    n = generalN;
    return;
  }
  const uint32_t   begin = mesh.neighbourOffsets[i];
  const uint32_t   end = mesh.neighbourOffsets[i + 1];
  const uint32_t * ring = mesh.neighbours;
  if (begin == end)
  {
    u = Vec4{};
    n = Vec4{};
    return;
  }
  // Relative to x_i, so that the cross products do not lose digits to the
  // distance from the origin. Lane 3 carries junk (the next coordinate in
  // memory) until cleared.
  const Vec4 xi = Load4(x + 3 * i);
  // Straight-line code for the usual valences.
  if (kind == ClosedRing && WithUsualValence(end - begin, [&](auto valence) {
        ClosedRingGeometry<decltype(valence)::value, NeedNormal>(x, ring + begin, xi, u, n);
      }))
  {
    return;
  }
  const Vec4 first = Load4(x + 3 * static_cast<SizeValueType>(ring[begin])) - xi;
  const Vec4 firstRotated = Rotate(first);
  Vec4       sum = first;
  Vec4       twisted{}; // sum of d_j * R(d_j+1) - R(d_j) * d_j+1; R(twisted) is sum of d_j x d_j+1
  Vec4       previous = first;
  Vec4       previousRotated = firstRotated;
  EDM_UNROLL_2
  for (uint32_t k = begin + 1; k < end; ++k)
  {
    const Vec4 d = Load4(x + 3 * static_cast<SizeValueType>(ring[k])) - xi;
    sum += d;
    if (NeedNormal)
    {
      const Vec4 rotated = Rotate(d);
      twisted += previous * rotated - previousRotated * d;
      previous = d;
      previousRotated = rotated;
    }
  }
  u = ClearLane3(sum * Splat(InverseCount(end - begin)));
  if (NeedNormal)
  {
    if (kind == ClosedRing)
    {
      twisted += previous * firstRotated - previousRotated * first;
    }
    n = ClearLane3(Rotate(twisted));
  }
}

// ---------------------------------------------------------------------------
// The two passes of a step, one work block at a time

/** Geometry pass over the vertices [begin, end) of a work block: umbrella
 * vectors (and outward unit normals) into arrays.umbrella (arrays.normals).
 * Ordered: each chunk in mesh.valenceOrder's order. */
template <bool NeedNormal, bool Ordered>
void
GeometryBlock(const MeshTables & mesh,
              const StepArrays & arrays,
              double             orientationSign,
              SizeValueType      begin,
              SizeValueType      end)
{
  const double *  x = arrays.coordinates;
  float *         umbrellaField = arrays.umbrella;
  float *         normalField = arrays.normals;
  const uint8_t * order = mesh.valenceOrder;
  // The normals of a chunk are scaled to unit length after the chunk: the
  // square roots and divisions then overlap across vertices instead of
  // ending each vertex's chain of dependent operations.
  Vec4 normals[ChunkSize];
  for (SizeValueType chunkBegin = begin; chunkBegin < end; chunkBegin += ChunkSize)
  {
    const SizeValueType chunkEnd = std::min(end, chunkBegin + ChunkSize);
    for (SizeValueType k = chunkBegin; k < chunkEnd; ++k)
    {
      const SizeValueType i = Ordered ? chunkBegin + order[k] : k;
      Vec4                u;
      Vec4                n;
      ComputeGeometry<NeedNormal>(mesh, x, i, u, n);
      StoreFloat4(umbrellaField + 4 * i, u);
      if (NeedNormal)
      {
        normals[i - chunkBegin] = n;
      }
    }
    if (NeedNormal)
    {
      for (SizeValueType i = chunkBegin; i < chunkEnd; ++i)
      {
        const double squaredLength = Dot3(normals[i - chunkBegin], normals[i - chunkBegin]);
        StoreFloat4(normalField + 4 * i,
                    squaredLength > 0.0 ? normals[i - chunkBegin] * Splat(orientationSign / std::sqrt(squaredLength))
                                        : Vec4{});
      }
    }
  }
}

/** The step of the vertices [begin, end) of a work block: new coordinates
 * into arrays.next, diagnostics when \a diagnose; returns their largest
 * displacement. UseRigidity: the umbrella vectors (and normals, with
 * UseNormal) come from the geometry pass. Ordered: each chunk in
 * mesh.valenceOrder's order.
 *
 * Per vertex, as DeformableMeshUpdateRule::Displacement():
 *   external force  s F(x)                           (SampleForces)
 *   rigidity        b (u - mean of the neighbours' u) (from the geometry pass)
 *   elasticity      a u, or a (u - (u.n) n) when tangential
 *   balloon         beta n until released, then 0; plus the image terms'
 *                   normal speed
 *   step bound      the displacement scaled down to maximumStep */
template <typename TPixel, bool UseRigidity, bool UseNormal, bool Ordered>
double
StepBlock(const ForceSampler<TPixel> & forceSampler,
          const MeshTables &           mesh,
          const StepTerms &            terms,
          const StepArrays &           arrays,
          SizeValueType                begin,
          SizeValueType                end,
          bool                         diagnose)
{
  // Everything the loop reads, in locals: the compiler cannot keep members in
  // registers across the stores to the output arrays.
  const double               elasticity = terms.elasticity;
  const double               rigidity = terms.rigidity;
  const bool                 useElasticity = elasticity > 0.0;
  const bool                 tangential = useElasticity && terms.tangential;
  const double               scaleFactor = terms.scaleFactor;
  const double               balloon = terms.balloon;
  const double               maximumStep = terms.maximumStep;
  const double               orientationSign = terms.orientationSign;
  const uint8_t *            order = mesh.valenceOrder;
  const ForceSampler<TPixel> sampler = forceSampler;
  const SamplerVectors       samplerVectors(sampler);
  const double *             x = arrays.coordinates;
  double *                   next = arrays.next;
  const float *              umbrellaField = arrays.umbrella;
  const float *              normalField = arrays.normals;
  const uint32_t *           offsets = mesh.neighbourOffsets;
  const uint32_t *           neighbours = mesh.neighbours;
  uint8_t *                  balloonReleased = arrays.balloonReleased;
  const float *              normalSpeeds = arrays.normalSpeeds;
  float *                    displacementMagnitudes = arrays.displacementMagnitudes;
  float *                    externalMagnitudes = arrays.externalMagnitudes;
  float *                    internalMagnitudes = arrays.internalMagnitudes;

  // The external forces of a chunk first, then the rest: two short loop
  // bodies whose long dependency chains (index, voxel loads, interpolation;
  // neighbour loads, normal) overlap across vertices.
  Vec4   externalForces[ChunkSize];
  double squaredSteps[ChunkSize];
  double largest = 0.0; // squared
  for (SizeValueType chunkBegin = begin; chunkBegin < end; chunkBegin += ChunkSize)
  {
    const SizeValueType chunkEnd = std::min(end, chunkBegin + ChunkSize);
    SampleForces(sampler, samplerVectors, x, chunkBegin, chunkEnd, scaleFactor, externalForces);
    for (SizeValueType k = chunkBegin; k < chunkEnd; ++k)
    {
      const SizeValueType i = Ordered ? chunkBegin + order[k] : k;
      const Vec4          xi = Load4(x + 3 * i);
      Vec4                u{};
      Vec4                n{};
      Vec4                internal{};
      if (UseRigidity)
      {
        u = LoadFloat4(umbrellaField + 4 * i);
        if (UseNormal)
        {
          n = LoadFloat4(normalField + 4 * i);
        }
        const uint32_t first = offsets[i];
        const uint32_t stop = offsets[i + 1];
        if (stop > first)
        {
          Vec4 sum{};
          if (!WithUsualValence(stop - first, [&](auto valence) {
                sum = GatherSum<decltype(valence)::value>(umbrellaField, neighbours + first);
              }))
          {
            for (uint32_t j = first; j < stop; ++j)
            {
              sum += LoadFloat4(umbrellaField + 4 * static_cast<SizeValueType>(neighbours[j]));
            }
          }
          internal = Splat(rigidity) * (u - sum * Splat(InverseCount(stop - first)));
        }
      }
      else if (UseNormal)
      {
        ComputeGeometry<true>(mesh, x, i, u, n);
        n = UnitVector(n, orientationSign);
      }
      else if (useElasticity)
      {
        ComputeGeometry<false>(mesh, x, i, u, n);
      }
      if (useElasticity)
      {
        const Vec4 e = tangential ? u - Dot4Splat(u, n) * n : u;
        internal += Splat(elasticity) * e;
      }

      const Vec4 external = externalForces[i - chunkBegin];
      // The balloon carries a vertex to an edge, not past it: once the
      // external force opposes it with half its strength, the vertex is in
      // the edge's capture range and the balloon is released for it.
      double inflation = 0.0;
      if (UseNormal && balloon != 0.0 && !balloonReleased[i])
      {
        if (balloon * Dot3(external, n) <= -0.5 * balloon * balloon)
        {
          balloonReleased[i] = 1;
        }
        else
        {
          inflation = balloon;
        }
      }
      if (UseNormal && normalSpeeds != nullptr)
      {
        inflation += normalSpeeds[i];
      }
      Vec4 delta = external + internal;
      if (UseNormal)
      {
        delta += Splat(inflation) * n;
      }
      if (maximumStep > 0.0)
      {
        const double length = std::sqrt(Dot3(delta, delta));
        if (length > maximumStep)
        {
          delta *= Splat(maximumStep / length);
        }
      }
      // A 4-wide store spills into the next point's first coordinate, which
      // the next iteration of this loop overwrites; not at the block's end,
      // nor when the vertices are not processed in order.
      if (!Ordered && i + 1 < end)
      {
        Store4(next + 3 * i, xi + delta);
      }
      else
      {
        Store3(next + 3 * i, xi + delta);
      }

      // Diagnostics, in single precision as they are stored: the three
      // lengths with one square root. The largest displacement is kept
      // squared.
      if (diagnose)
      {
        const Vec4 squares = SquaredLengths(delta, external, internal);
        SqrtStore3(squares, displacementMagnitudes + i, externalMagnitudes + i, internalMagnitudes + i);
        squaredSteps[i - chunkBegin] = squares[0];
      }
      else
      {
        squaredSteps[i - chunkBegin] = Dot3(delta, delta);
      }
    }
    // Apart from the loop above: a running maximum there is a dependency
    // chain through memory when the registers run short.
    for (SizeValueType k = 0; k < chunkEnd - chunkBegin; ++k)
    {
      largest = std::max(largest, squaredSteps[k]);
    }
  }
  return std::sqrt(largest);
}
