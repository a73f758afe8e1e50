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

// Scores a segmentation surface against a reference segmentation on real
// images: Dice of the surface's interior (voxelised on the reference's grid)
// with the reference's non-zero voxels, and the mean and 95th percentile of
// the distance from the surface's vertices to the reference's boundary (mm).
//
//   edmScore info REFERENCE
//     centre (physical, mm) and volume of the reference's non-zero voxels
//   edmScore score MESH REFERENCE [--min-dice D] [--max-mean MM]
//     prints "dice D mean MM p95 MM vertices N"; exit 1 when a limit fails

#include "itkBinaryThresholdImageFilter.h"
#include "itkImage.h"
#include "itkImageFileReader.h"
#include "itkImageFileWriter.h"
#include "itkImageRegionConstIteratorWithIndex.h"
#include "itkLinearInterpolateImageFunction.h"
#include "itkMesh.h"
#include "itkMeshFileReader.h"
#include "itkSignedMaurerDistanceMapImageFilter.h"
#include "itkTriangleMeshToBinaryImageFilter.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

namespace
{
using ImageType = itk::Image<float, 3>;
using MaskType = itk::Image<unsigned char, 3>;
using MeshType = itk::Mesh<float, 3>;

MaskType::Pointer
ReadMask(const std::string & path)
{
  auto reader = itk::ImageFileReader<ImageType>::New();
  reader->SetFileName(path);
  auto threshold = itk::BinaryThresholdImageFilter<ImageType, MaskType>::New();
  threshold->SetInput(reader->GetOutput());
  // Non-zero voxels: strictly above zero (the skull-stripped images hold
  // non-negative intensities and exact zeros outside).
  threshold->SetLowerThreshold(std::nextafter(0.0f, 1.0f));
  threshold->SetUpperThreshold(itk::NumericTraits<float>::max());
  threshold->SetInsideValue(1);
  threshold->SetOutsideValue(0);
  threshold->Update();
  return threshold->GetOutput();
}

int
Info(const std::string & referencePath)
{
  const MaskType::Pointer mask = ReadMask(referencePath);
  double                  sum[3] = { 0.0, 0.0, 0.0 };
  double                  count = 0.0;
  for (itk::ImageRegionConstIteratorWithIndex<MaskType> it(mask, mask->GetLargestPossibleRegion()); !it.IsAtEnd(); ++it)
  {
    if (it.Get() != 0)
    {
      MaskType::PointType p;
      mask->TransformIndexToPhysicalPoint(it.GetIndex(), p);
      for (unsigned int k = 0; k < 3; ++k)
      {
        sum[k] += p[k];
      }
      count += 1.0;
    }
  }
  const double voxel = mask->GetSpacing()[0] * mask->GetSpacing()[1] * mask->GetSpacing()[2];
  std::cout << "centre " << sum[0] / count << "," << sum[1] / count << "," << sum[2] / count << " volume "
            << count * voxel << " mm3" << std::endl;
  return EXIT_SUCCESS;
}

int
Score(const std::string & meshPath,
      const std::string & referencePath,
      double              minDice,
      double              maxMean,
      const std::string & maskPath)
{
  const MaskType::Pointer reference = ReadMask(referencePath);
  auto                    meshReader = itk::MeshFileReader<MeshType>::New();
  meshReader->SetFileName(meshPath);
  meshReader->Update();
  const MeshType::Pointer mesh = meshReader->GetOutput();

  auto voxelise = itk::TriangleMeshToBinaryImageFilter<MeshType, MaskType>::New();
  voxelise->SetInput(mesh);
  voxelise->SetInfoImage(reference);
  voxelise->SetInsideValue(1);
  voxelise->SetOutsideValue(0);
  voxelise->Update();
  const MaskType * segmentation = voxelise->GetOutput();
  if (!maskPath.empty())
  {
    auto writer = itk::ImageFileWriter<MaskType>::New();
    writer->SetInput(segmentation);
    writer->SetFileName(maskPath);
    writer->Update();
  }

  double                                           both = 0.0;
  double                                           inReference = 0.0;
  double                                           inSegmentation = 0.0;
  itk::ImageRegionConstIteratorWithIndex<MaskType> r(reference, reference->GetLargestPossibleRegion());
  itk::ImageRegionConstIteratorWithIndex<MaskType> s(segmentation, reference->GetLargestPossibleRegion());
  for (; !r.IsAtEnd(); ++r, ++s)
  {
    const bool a = r.Get() != 0;
    const bool b = s.Get() != 0;
    both += a && b ? 1.0 : 0.0;
    inReference += a ? 1.0 : 0.0;
    inSegmentation += b ? 1.0 : 0.0;
  }
  const double dice = 2.0 * both / (inReference + inSegmentation);

  // Distance to the boundary between voxel centres in and out: the signed
  // distance map of the voxel centres is offset by half a voxel on each side,
  // so the mean of the two maps' values places the boundary midway.
  auto distance = itk::SignedMaurerDistanceMapImageFilter<MaskType, ImageType>::New();
  distance->SetInput(reference);
  distance->SetUseImageSpacing(true);
  distance->SetSquaredDistance(false);
  distance->SetInsideIsPositive(false);
  distance->Update();
  auto interpolator = itk::LinearInterpolateImageFunction<ImageType, double>::New();
  interpolator->SetInputImage(distance->GetOutput());
  const double        halfVoxel = 0.5 * reference->GetSpacing()[0];
  std::vector<double> distances;
  size_t              farOutside = 0; // more than 2 mm outside the reference
  size_t              farInside = 0;
  for (auto it = mesh->GetPoints()->Begin(); it != mesh->GetPoints()->End(); ++it)
  {
    itk::Point<double, 3> p;
    for (unsigned int k = 0; k < 3; ++k)
    {
      p[k] = it.Value()[k];
    }
    itk::ContinuousIndex<double, 3> index;
    if (!reference->TransformPhysicalPointToContinuousIndex(p, index) || !interpolator->IsInsideBuffer(index))
    {
      distances.push_back(1e3);
      continue;
    }
    // Maurer's map is 0.5 voxel on the first voxel outside and -0.5 on the
    // first inside (with image spacing, in mm): shift by half a voxel.
    const double d = interpolator->EvaluateAtContinuousIndex(index);
    farOutside += d > 2.0 + halfVoxel ? 1 : 0;
    farInside += d < -2.0 - halfVoxel ? 1 : 0;
    distances.push_back(std::abs(d > 0.0 ? d - halfVoxel : d + halfVoxel));
  }
  double mean = 0.0;
  for (double d : distances)
  {
    mean += d;
  }
  mean /= static_cast<double>(distances.size());
  std::sort(distances.begin(), distances.end());
  const double p95 = distances[static_cast<size_t>(0.95 * (distances.size() - 1))];
  std::cout << "dice " << dice << " mean " << mean << " p95 " << p95 << " vertices " << distances.size()
            << " outside2mm " << farOutside << " inside2mm " << farInside << std::endl;
  bool good = true;
  if (dice < minDice)
  {
    std::cout << "FAIL: Dice " << dice << " below " << minDice << std::endl;
    good = false;
  }
  if (mean > maxMean)
  {
    std::cout << "FAIL: mean distance " << mean << " mm above " << maxMean << std::endl;
    good = false;
  }
  return good ? EXIT_SUCCESS : EXIT_FAILURE;
}
} // namespace

int
main(int argc, char * argv[])
{
  try
  {
    const std::string command = argc > 1 ? argv[1] : "";
    if (command == "info" && argc == 3)
    {
      return Info(argv[2]);
    }
    if (command == "score" && argc >= 4)
    {
      double      minDice = 0.0;
      double      maxMean = 1e300;
      std::string maskPath;
      for (int i = 4; i + 1 < argc; i += 2)
      {
        const std::string name = argv[i];
        if (name == "--min-dice")
        {
          minDice = std::stod(argv[i + 1]);
        }
        else if (name == "--max-mean")
        {
          maxMean = std::stod(argv[i + 1]);
        }
        else if (name == "--write-mask")
        {
          maskPath = argv[i + 1];
        }
        else
        {
          std::cerr << "edmScore: unknown option " << name << std::endl;
          return 2;
        }
      }
      return Score(argv[2], argv[3], minDice, maxMean, maskPath);
    }
  }
  catch (const std::exception & error)
  {
    std::cerr << "edmScore: " << error.what() << std::endl;
    return 2;
  }
  std::cerr << "usage: edmScore info REFERENCE | edmScore score MESH REFERENCE [--min-dice D] [--max-mean MM] "
               "[--write-mask MASK]"
            << std::endl;
  return 2;
}
