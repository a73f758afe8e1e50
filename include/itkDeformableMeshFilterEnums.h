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
#ifndef itkDeformableMeshFilterEnums_h
#define itkDeformableMeshFilterEnums_h

#include <cstdint>
#include <ostream>

namespace itk
{

/** \class DeformableMeshFilterEnums
 * \brief Enumerations of DeformableMeshFilter's parameters, outside the
 * class template so that all its instantiations share them.
 * \ingroup ExplicitDeformableModel
 */
class DeformableMeshFilterEnums
{
public:
  /** \class TangentialDrift
   * \brief What becomes of the external force's component tangent to the
   * surface where the surface has come to rest
   * (DeformableMeshFilter::SetTangentialDrift()).
   * \ingroup ExplicitDeformableModel */
  enum class TangentialDrift : uint8_t
  {
    /** The external force acts whole everywhere. */
    Keep = 0,
    /** Dropped at rest, always. */
    Suppress = 1,
    /** Dropped at rest when the filter remeshes (RemeshingEdgeLength > 0),
     * kept otherwise: the default. */
    SuppressWhenRemeshing = 2
  };
};

/** Prints the enumerator's name, e.g. "Keep". */
inline std::ostream &
operator<<(std::ostream & out, const DeformableMeshFilterEnums::TangentialDrift value)
{
  switch (value)
  {
    case DeformableMeshFilterEnums::TangentialDrift::Keep:
      return out << "Keep";
    case DeformableMeshFilterEnums::TangentialDrift::Suppress:
      return out << "Suppress";
    case DeformableMeshFilterEnums::TangentialDrift::SuppressWhenRemeshing:
      return out << "SuppressWhenRemeshing";
  }
  return out << "TangentialDrift(" << static_cast<int>(value) << ")";
}

} // end namespace itk

#endif // itkDeformableMeshFilterEnums_h
