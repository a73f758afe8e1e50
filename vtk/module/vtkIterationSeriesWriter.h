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
#ifndef vtkIterationSeriesWriter_h
#define vtkIterationSeriesWriter_h

#include "ExplicitDeformableModelVTKModule.h" // For export macro
#include "vtkObject.h"

class vtkIterationSeriesWriterInternals;
class vtkIterativePolyDataAlgorithm;
class vtkPolyData;

/**
 * @class vtkIterationSeriesWriter
 * @brief Writes iterations of a deformation as VTK XML polydata files (.vtp)
 * and a ParaView data collection (.pvd) that plays them back in time.
 *
 * FileName is the collection, for example "run/sphere.pvd"; the iterations go
 * beside it as "run/sphere_000010.vtp" (six-digit iteration number) and the
 * collection refers to them by relative name, with the iteration number as
 * the time step. The directory must exist.
 *
 * Two ways to use it:
 * - Write() drives a vtkIterativePolyDataAlgorithm: from iteration 0, every
 *   Interval-th iteration up to NumberOfIterations (the last one is always
 *   written), each reached with one more step thanks to IterateFromZero off.
 *   When the algorithm stops early (convergence), the iteration it stopped at
 *   is the last one written. The algorithm's IterateFromZero and
 *   NumberOfIterations are restored afterwards. A vtkDeformableMesh on 2-D
 *   contours is driven the same way: each file holds the contours' lines in
 *   the image's plane.
 * - WriteIteration() for each mesh produced elsewhere (for example an ITK
 *   filter observed at each iteration, its mesh converted with
 *   edm::MeshToPolyData), then WriteCollection().
 *
 * Errors are reported with vtkErrorMacro and a return value of 0.
 *
 * @sa vtkIterativePolyDataAlgorithm vtkXMLPolyDataWriter
 */
class EXPLICITDEFORMABLEMODELVTK_EXPORT vtkIterationSeriesWriter : public vtkObject
{
public:
  static vtkIterationSeriesWriter *
  New();
  vtkTypeMacro(vtkIterationSeriesWriter, vtkObject);
  void
  PrintSelf(ostream & os, vtkIndent indent) override;

  ///@{
  /**
   * Path of the .pvd collection; the .vtp files are written beside it.
   * Default: none (required).
   */
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  ///@{
  /**
   * Write every Interval-th iteration (K). At least 1. Default: 1.
   */
  vtkSetClampMacro(Interval, int, 1, VTK_INT_MAX);
  vtkGetMacro(Interval, int);
  ///@}

  ///@{
  /**
   * Last iteration Write() asks of the algorithm. Default: 0 (only the
   * input is written).
   */
  vtkSetClampMacro(NumberOfIterations, int, 0, VTK_INT_MAX);
  vtkGetMacro(NumberOfIterations, int);
  ///@}

  ///@{
  /**
   * Binary (appended, compressed) .vtp files when on (default), ASCII when off.
   */
  vtkSetMacro(Binary, vtkTypeBool);
  vtkGetMacro(Binary, vtkTypeBool);
  vtkBooleanMacro(Binary, vtkTypeBool);
  ///@}

  ///@{
  /**
   * The algorithm Write() drives.
   */
  virtual void
  SetAlgorithm(vtkIterativePolyDataAlgorithm * algorithm);
  vtkGetObjectMacro(Algorithm, vtkIterativePolyDataAlgorithm);
  ///@}

  /**
   * Runs the algorithm and writes the series and the collection. Returns 1 on
   * success.
   */
  int
  Write();

  /**
   * Writes one iteration's mesh as a .vtp file and adds it to the collection.
   * Returns 1 on success.
   */
  int
  WriteIteration(vtkPolyData * mesh, int iteration);

  /**
   * Writes the .pvd collection of the files written since the last
   * ClearCollection(). Returns 1 on success.
   */
  int
  WriteCollection();

  /**
   * Forgets the files written so far (the files stay on disk).
   */
  void
  ClearCollection();

  /**
   * Number of .vtp files in the collection, and the path of the k-th one.
   */
  int
  GetNumberOfWrittenFiles();
  const char *
  GetWrittenFileName(int k);

  /**
   * Iteration number of the k-th file of the collection (-1 if k is out of
   * range).
   */
  int
  GetWrittenIteration(int k);

protected:
  vtkIterationSeriesWriter();
  ~vtkIterationSeriesWriter() override;

  char *                              FileName = nullptr;
  int                                 Interval = 1;
  int                                 NumberOfIterations = 0;
  vtkTypeBool                         Binary = 1;
  vtkIterativePolyDataAlgorithm *     Algorithm = nullptr;
  vtkIterationSeriesWriterInternals * Internals;

private:
  vtkIterationSeriesWriter(const vtkIterationSeriesWriter &) = delete;
  void
  operator=(const vtkIterationSeriesWriter &) = delete;
};

#endif
