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
#ifndef itkEllipsoidPhantom_h
#define itkEllipsoidPhantom_h

#include "itkImage.h"
#include "itkImageRegionIteratorWithIndex.h"
#include "itkMatrix.h"
#include "itkRegularSphereMeshSource.h"

#include <algorithm>
#include <cmath>

namespace itk
{

/** \class EllipsoidPhantom
 * \brief An ellipsoid in physical space, with the tools to test a deformable
 * model against it: a binary image of it, a sphere mesh to start from, and
 * the exact Euclidean distance from a point to its surface.
 *
 * The ellipsoid is \f$ \{ c + A y : \sum_k (y_k / r_k)^2 \le 1 \} \f$ with
 * centre c, semi-axes r (physical units) and an orthonormal axis matrix A whose
 * columns are the ellipsoid's axes (identity by default).
 *
 * \ingroup ExplicitDeformableModel
 */
class EllipsoidPhantom
{
public:
  using PointType = Point<double, 3>;
  using VectorType = Vector<double, 3>;
  using MatrixType = Matrix<double, 3, 3>;

  EllipsoidPhantom(const PointType &  center,
                   const VectorType & radii,
                   const MatrixType & axes = MatrixType::GetIdentity())
    : m_Center(center)
    , m_Radii(radii)
    , m_Axes(axes)
  {}

  const PointType &
  GetCenter() const
  {
    return m_Center;
  }
  const VectorType &
  GetRadii() const
  {
    return m_Radii;
  }
  const MatrixType &
  GetAxes() const
  {
    return m_Axes;
  }

  /** Coordinates of p in the ellipsoid's frame. */
  VectorType
  ToLocal(const PointType & p) const
  {
    VectorType local;
    for (unsigned int i = 0; i < 3; ++i)
    {
      local[i] = 0.0;
      for (unsigned int k = 0; k < 3; ++k)
      {
        local[i] += m_Axes(k, i) * (p[k] - m_Center[k]);
      }
    }
    return local;
  }

  bool
  IsInside(const PointType & p) const
  {
    const VectorType y = this->ToLocal(p);
    double           s = 0.0;
    for (unsigned int k = 0; k < 3; ++k)
    {
      s += (y[k] / m_Radii[k]) * (y[k] / m_Radii[k]);
    }
    return s <= 1.0;
  }

  /** Euclidean distance from p to the ellipsoid's surface (physical units).
   * In the frame of the semi-axes a_k, with z the absolute coordinates of p,
   * the closest point is x_k = a_k^2 z_k / (t + a_k^2) for the root t of
   * g(t) = sum (a_k z_k / (t + a_k^2))^2 - 1 above -a_min^2, found by
   * bisection. One case has no such root: a point (inside the ellipsoid)
   * whose coordinates along the shortest semi-axes are zero and which lies
   * near enough to the centre that g stays below 0 down to -a_min^2. Its
   * closest points then leave the plane of those axes: t = -a_min^2, the
   * other coordinates as above, and the shortest axes' part of the closest
   * point of length a_min sqrt(1 - sum over the other axes of (x_k / a_k)^2)
   * (a point on the long axis of an elongated ellipsoid, say: its closest
   * points lie on a ring around that axis). */
  double
  DistanceToSurface(const PointType & p) const
  {
    const VectorType y = this->ToLocal(p);
    double           z[3];
    double           a2[3];
    for (unsigned int k = 0; k < 3; ++k)
    {
      z[k] = std::abs(y[k]);
      a2[k] = m_Radii[k] * m_Radii[k];
    }
    const double smallest = std::min({ a2[0], a2[1], a2[2] });
    const auto   isShortest = [&](unsigned int k) { return a2[k] <= smallest * (1.0 + 1e-12); };

    // The degenerate case: zero coordinates along the shortest semi-axes.
    double shortestPart = 0.0;
    double offPlane = 0.0;
    for (unsigned int k = 0; k < 3; ++k)
    {
      if (isShortest(k))
      {
        shortestPart += z[k] * z[k];
      }
      else
      {
        const double q = m_Radii[k] * z[k] / (a2[k] - smallest);
        offPlane += q * q;
      }
    }
    if (shortestPart <= 1e-18 * smallest && offPlane < 1.0)
    {
      double d2 = smallest * (1.0 - offPlane);
      for (unsigned int k = 0; k < 3; ++k)
      {
        if (!isShortest(k))
        {
          const double closest = a2[k] * z[k] / (a2[k] - smallest);
          d2 += (closest - z[k]) * (closest - z[k]);
        }
      }
      return std::sqrt(d2);
    }

    // g(t) decreases on (-a_min^2, inf), from +inf (or from g(-a_min^2) >= 0
    // in the degenerate case's other half) to -1.
    auto g = [&](double t) {
      double s = 0.0;
      for (unsigned int k = 0; k < 3; ++k)
      {
        const double q = m_Radii[k] * z[k] / (t + a2[k]);
        s += q * q;
      }
      return s - 1.0;
    };
    const double norm = std::sqrt(z[0] * z[0] + z[1] * z[1] + z[2] * z[2]);
    double       low = -smallest;
    double       high = std::sqrt(std::max({ a2[0], a2[1], a2[2] })) * norm + 1.0;
    for (int iteration = 0; iteration < 200; ++iteration)
    {
      const double middle = 0.5 * (low + high);
      if (middle <= -smallest || g(middle) > 0.0)
      {
        low = middle;
      }
      else
      {
        high = middle;
      }
    }
    const double t = 0.5 * (low + high);
    double       d2 = 0.0;
    for (unsigned int k = 0; k < 3; ++k)
    {
      const double denominator = t + a2[k];
      const double closest = denominator > 0.0 ? std::min(a2[k] * z[k] / denominator, m_Radii[k]) : 0.0;
      d2 += (z[k] - closest) * (z[k] - closest);
    }
    return std::sqrt(d2);
  }

  /** Binary image of the ellipsoid: voxels whose centre is inside get
   * \a inside, the others \a outside. */
  template <typename TImage>
  typename TImage::Pointer
  MakeImage(const typename TImage::SizeType &      size,
            const typename TImage::SpacingType &   spacing,
            const typename TImage::PointType &     origin,
            const typename TImage::DirectionType & direction,
            typename TImage::PixelType             inside = 1,
            typename TImage::PixelType             outside = 0) const
  {
    auto image = TImage::New();
    image->SetRegions(size);
    image->SetSpacing(spacing);
    image->SetOrigin(origin);
    image->SetDirection(direction);
    image->Allocate();
    for (ImageRegionIteratorWithIndex<TImage> it(image, image->GetBufferedRegion()); !it.IsAtEnd(); ++it)
    {
      typename TImage::PointType p;
      image->TransformIndexToPhysicalPoint(it.GetIndex(), p);
      PointType q;
      q.CastFrom(p);
      it.Set(this->IsInside(q) ? inside : outside);
    }
    return image;
  }

  /** Mean and largest distance of a mesh's points to the surface. */
  template <typename TMesh>
  void
  MeasureDistance(const TMesh * mesh, double & meanDistance, double & maximumDistance) const
  {
    meanDistance = 0.0;
    maximumDistance = 0.0;
    const auto * points = mesh->GetPoints();
    for (auto it = points->Begin(); it != points->End(); ++it)
    {
      PointType p;
      p.CastFrom(it.Value());
      const double d = this->DistanceToSurface(p);
      meanDistance += d;
      maximumDistance = std::max(maximumDistance, d);
    }
    meanDistance /= std::max<double>(1.0, static_cast<double>(points->Size()));
  }

private:
  PointType  m_Center;
  VectorType m_Radii;
  MatrixType m_Axes;
};

/** A triangulated sphere of the given centre and radius (physical units):
 * itk::RegularSphereMeshSource's octahedron subdivided \a resolution times,
 * 4^(resolution + 1) + 2 points (1026 for resolution 4). */
template <typename TMesh>
typename TMesh::Pointer
MakeSphereMesh(const typename TMesh::PointType & center, double radius, unsigned int resolution = 4)
{
  using SourceType = RegularSphereMeshSource<TMesh>;
  auto                            source = SourceType::New();
  typename SourceType::VectorType scale;
  scale.Fill(radius);
  source->SetCenter(center);
  source->SetScale(scale);
  source->SetResolution(resolution);
  source->Update();
  typename TMesh::Pointer mesh = source->GetOutput();
  mesh->DisconnectPipeline();
  return mesh;
}

} // end namespace itk

#endif
