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
#include "vtkPolyDataIterativeWarp.h"

#include "vtkIterativePolyDataAlgorithmInternals.h"

#include "itkBrownianMeshFilter.h"

#include "vtkObjectFactory.h"

#include <cstdint>

vtkStandardNewMacro(vtkPolyDataIterativeWarp);

namespace
{
using BrownianFilterType = itk::BrownianMeshFilter<vtkIterativePolyDataAlgorithmInternals::MeshType>;
}

//------------------------------------------------------------------------------
vtkPolyDataIterativeWarp::vtkPolyDataIterativeWarp()
{
  this->Internals->Filter = BrownianFilterType::New();
}

//------------------------------------------------------------------------------
int
vtkPolyDataIterativeWarp::PrepareFilter(vtkInformationVector **)
{
  auto * filter = static_cast<BrownianFilterType *>(this->Internals->Filter.GetPointer());
  filter->SetStepLength(this->StepLength);
  filter->SetSeed(static_cast<uint64_t>(this->Seed));
  return 1;
}

//------------------------------------------------------------------------------
void
vtkPolyDataIterativeWarp::PrintSelf(ostream & os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "StepLength: " << this->StepLength << "\n";
  os << indent << "Seed: " << this->Seed << "\n";
}
