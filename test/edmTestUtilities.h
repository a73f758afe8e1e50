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
#ifndef edmTestUtilities_h
#define edmTestUtilities_h

// Helpers shared by the module's GoogleTests.

#include "itkMacro.h"
#include "itkMatrix.h"

#include <cmath>
#include <string>

namespace edm
{
namespace test
{
/** A direction matrix: rotation of \a angle radians about the unit axis \a u. */
inline itk::Matrix<double, 3, 3>
Rotation(double angle, const double (&u)[3])
{
  const double              c = std::cos(angle);
  const double              s = std::sin(angle);
  itk::Matrix<double, 3, 3> r;
  for (unsigned int i = 0; i < 3; ++i)
  {
    for (unsigned int j = 0; j < 3; ++j)
    {
      r(i, j) = (i == j ? c : 0.0) + (1.0 - c) * u[i] * u[j];
    }
  }
  r(0, 1) -= s * u[2];
  r(0, 2) += s * u[1];
  r(1, 0) += s * u[2];
  r(1, 2) -= s * u[0];
  r(2, 0) -= s * u[1];
  r(2, 1) += s * u[0];
  return r;
}

/** Updates \a filter; returns the description of the exception it throws,
 * or an empty string. */
template <typename TFilter>
inline std::string
UpdateAndGetError(TFilter * filter)
{
  try
  {
    filter->Update();
  }
  catch (const itk::ExceptionObject & e)
  {
    return e.GetDescription();
  }
  return "";
}

} // namespace test
} // namespace edm

#endif
