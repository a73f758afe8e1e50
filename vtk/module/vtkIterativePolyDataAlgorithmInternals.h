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
#ifndef vtkIterativePolyDataAlgorithmInternals_h
#define vtkIterativePolyDataAlgorithmInternals_h

#include "edmMeshBridge.h"
#include "itkIterativeMeshFilter.h"

#include "vtkType.h"

class vtkPolyData;

/**
 * True once the process has begun to exit (static destruction). ParaView's
 * pvpython destroys its proxies, and with them our VTK objects, from a static
 * of a library loaded before this module, hence after ITK's globals (time
 * stamp, singletons) are gone: destroying an ITK object then crashes. A static
 * of this module, destroyed before the statics of the libraries loaded before
 * it (ParaView's), sets the flag; the destructors then leave the ITK objects
 * to the operating system.
 */
bool
edmProcessIsExiting();

/**
 * The ITK side of a vtkIterativePolyDataAlgorithm (private header): the mesh
 * types the VTK classes compute with, the ITK filters of the subclass, and the
 * ITK mesh converted from the VTK input, kept while the input (and the
 * dimension of the model) does not change so that the ITK filter can continue
 * its iterations.
 *
 * Two dimensions: surfaces (and curves) in 3-D go through Filter, contours
 * over a 2-D image through ContourFilter, which only the subclasses that
 * deform contours create. One of InputMesh and InputContourMesh is set at a
 * time.
 */
class vtkIterativePolyDataAlgorithmInternals
{
public:
  using MeshType = edm::PolyDataMeshType;       // 3-D, double coordinates
  using ContourMeshType = edm::ContourMeshType; // 2-D, double coordinates
  using FilterType = itk::IterativeMeshFilter<MeshType, MeshType>;
  using ContourFilterType = itk::IterativeMeshFilter<ContourMeshType, ContourMeshType>;

  FilterType::Pointer        Filter;
  ContourFilterType::Pointer ContourFilter;
  MeshType::Pointer          InputMesh;
  ContourMeshType::Pointer   InputContourMesh;
  // Identity and modification time of the vtkPolyData the cached mesh was made from.
  const vtkPolyData * InputPolyData = nullptr;
  vtkMTimeType        InputTime = 0;
};

#endif
