
// Helper of the edmodel tests: writes the images and meshes the tests feed to
// edmodel, and measures edmodel's output mesh against the exact ellipsoid.
//
//   edmodelTestTool phantom IMG --size X,Y,Z --spacing X,Y,Z --origin X,Y,Z
//                   [--direction 9 numbers, row by row] --center X,Y,Z --radii A,B,C
//                   [--axes 9 numbers] [--inside V] [--outside V] [--pixel float|short|double]
//                   [--noise S]   (Gaussian noise of standard deviation S, fixed seed)
//   edmodelTestTool dicom DIR (same options as phantom, 16-bit slices)
//   edmodelTestTool sphere MESH --center X,Y,Z --radius R [--resolution N]
//   edmodelTestTool lines MESH          (points and lines: no triangle)
//   edmodelTestTool flat IMG            (a 2-D image)
//   edmodelTestTool measure MESH --center X,Y,Z --radii A,B,C [--axes 9 numbers]
//                   --max-mean D --max-max D [--min-points N]
//
// Distances are physical (mm). measure exits with 1 when a limit is exceeded.

#include "itkEllipsoidPhantom.h"
#include "itkGDCMImageIO.h"
#include "itkImageFileWriter.h"
#include "itkImageSeriesWriter.h"
#include "itkLineCell.h"
#include "itkMesh.h"
#include "itkMeshFileReader.h"
#include "itkMeshFileWriter.h"
#include "itkMetaDataObject.h"

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace
{

using MeshType = itk::Mesh<double, 3, itk::DefaultStaticMeshTraits<double, 3, 3, double, double>>;

std::vector<double>
Numbers(const std::map<std::string, std::string> & options, const std::string & name, size_t count)
{
  const auto found = options.find(name);
  if (found == options.end())
  {
    throw std::runtime_error("missing " + name);
  }
  std::vector<double> values;
  std::istringstream  stream(found->second);
  std::string         item;
  while (std::getline(stream, item, ','))
  {
    values.push_back(std::stod(item));
  }
  if (values.size() != count)
  {
    throw std::runtime_error(name + " needs " + std::to_string(count) + " numbers");
  }
  return values;
}

itk::Matrix<double, 3, 3>
Matrix(const std::map<std::string, std::string> & options, const std::string & name)
{
  itk::Matrix<double, 3, 3> matrix;
  matrix.SetIdentity();
  if (options.count(name) != 0)
  {
    const auto v = Numbers(options, name, 9);
    for (unsigned int r = 0; r < 3; ++r)
    {
      for (unsigned int c = 0; c < 3; ++c)
      {
        matrix(r, c) = v[3 * r + c];
      }
    }
  }
  return matrix;
}

itk::EllipsoidPhantom
Phantom(const std::map<std::string, std::string> & options)
{
  const auto                        c = Numbers(options, "--center", 3);
  const auto                        r = Numbers(options, "--radii", 3);
  itk::EllipsoidPhantom::PointType  center;
  itk::EllipsoidPhantom::VectorType radii;
  for (unsigned int k = 0; k < 3; ++k)
  {
    center[k] = c[k];
    radii[k] = r[k];
  }
  return itk::EllipsoidPhantom(center, radii, Matrix(options, "--axes"));
}

template <typename TPixel>
typename itk::Image<TPixel, 3>::Pointer
MakePhantomImage(const std::map<std::string, std::string> & options)
{
  using ImageType = itk::Image<TPixel, 3>;
  const auto                        size = Numbers(options, "--size", 3);
  const auto                        spacing = Numbers(options, "--spacing", 3);
  const auto                        origin = Numbers(options, "--origin", 3);
  typename ImageType::SizeType      imageSize;
  typename ImageType::SpacingType   imageSpacing;
  typename ImageType::PointType     imageOrigin;
  typename ImageType::DirectionType direction = Matrix(options, "--direction");
  for (unsigned int k = 0; k < 3; ++k)
  {
    imageSize[k] = static_cast<itk::SizeValueType>(size[k]);
    imageSpacing[k] = spacing[k];
    imageOrigin[k] = origin[k];
  }
  const double inside = options.count("--inside") ? std::stod(options.at("--inside")) : 1.0;
  const double outside = options.count("--outside") ? std::stod(options.at("--outside")) : 0.0;
  auto         image = Phantom(options).MakeImage<ImageType>(
    imageSize, imageSpacing, imageOrigin, direction, static_cast<TPixel>(inside), static_cast<TPixel>(outside));
  const double noise = options.count("--noise") ? std::stod(options.at("--noise")) : 0.0;
  if (noise > 0.0)
  {
    // A fixed seed: the same image on every run and every machine (mt19937's
    // sequence is specified; the normal distribution's transform is the
    // library's, the same on the one compiler CI uses).
    std::mt19937                     generator(20261202u);
    std::normal_distribution<double> normal(0.0, noise);
    TPixel *                         pixel = image->GetBufferPointer();
    for (size_t i = 0, n = image->GetPixelContainer()->Size(); i < n; ++i)
    {
      pixel[i] = static_cast<TPixel>(static_cast<double>(pixel[i]) + normal(generator));
    }
  }
  return image;
}

template <typename TPixel>
void
WritePhantom(const std::string & path, const std::map<std::string, std::string> & options)
{
  using ImageType = itk::Image<TPixel, 3>;
  auto image = MakePhantomImage<TPixel>(options);
  auto writer = itk::ImageFileWriter<ImageType>::New();
  writer->SetInput(image);
  writer->SetFileName(path);
  writer->Update();
}

/** One DICOM file per slice, with the position and orientation tags that
 * give the volume its physical frame back when the series is read. */
void
WriteDicomSeries(const std::string & directory, const std::map<std::string, std::string> & options)
{
  using ImageType = itk::Image<short, 3>;
  using SliceType = itk::Image<short, 2>;
  auto                                                              image = MakePhantomImage<short>(options);
  const auto &                                                      direction = image->GetDirection();
  const auto                                                        size = image->GetLargestPossibleRegion().GetSize();
  std::vector<std::unique_ptr<itk::MetaDataDictionary>>             dictionaries;
  itk::ImageSeriesWriter<ImageType, SliceType>::DictionaryArrayType dictionaryArray;
  std::vector<std::string>                                          names;
  std::ostringstream                                                orientation;
  orientation << direction(0, 0) << "\\" << direction(1, 0) << "\\" << direction(2, 0) << "\\" << direction(0, 1)
              << "\\" << direction(1, 1) << "\\" << direction(2, 1);
  for (unsigned int z = 0; z < size[2]; ++z)
  {
    ImageType::IndexType index = { { 0, 0, static_cast<itk::IndexValueType>(z) } };
    ImageType::PointType position;
    image->TransformIndexToPhysicalPoint(index, position);
    std::ostringstream positionText;
    positionText << position[0] << "\\" << position[1] << "\\" << position[2];
    auto dictionary = std::make_unique<itk::MetaDataDictionary>();
    itk::EncapsulateMetaData<std::string>(*dictionary, "0008|0060", "CT");
    itk::EncapsulateMetaData<std::string>(*dictionary, "0020|000d", "1.2.826.0.1.3680043.9.7133.1");
    itk::EncapsulateMetaData<std::string>(*dictionary, "0020|000e", "1.2.826.0.1.3680043.9.7133.1.1");
    itk::EncapsulateMetaData<std::string>(
      *dictionary, "0008|0018", "1.2.826.0.1.3680043.9.7133.1.1." + std::to_string(z + 1));
    itk::EncapsulateMetaData<std::string>(*dictionary, "0020|0013", std::to_string(z + 1));
    itk::EncapsulateMetaData<std::string>(*dictionary, "0028|0004", "MONOCHROME2");
    itk::EncapsulateMetaData<std::string>(*dictionary, "0020|0032", positionText.str());
    itk::EncapsulateMetaData<std::string>(*dictionary, "0020|0037", orientation.str());
    itk::EncapsulateMetaData<std::string>(*dictionary, "0018|0050", std::to_string(image->GetSpacing()[2]));
    dictionaryArray.push_back(dictionary.get());
    dictionaries.push_back(std::move(dictionary));
    names.push_back(directory + "/slice" + std::to_string(1000 + z) + ".dcm");
  }
  std::filesystem::create_directories(directory);
  auto io = itk::GDCMImageIO::New();
  io->KeepOriginalUIDOn();
  auto writer = itk::ImageSeriesWriter<ImageType, SliceType>::New();
  writer->SetInput(image);
  writer->SetImageIO(io);
  writer->SetFileNames(names);
  writer->SetMetaDataDictionaryArray(&dictionaryArray);
  writer->Update();
}

int
Measure(const std::string & path, const std::map<std::string, std::string> & options)
{
  auto reader = itk::MeshFileReader<MeshType>::New();
  reader->SetFileName(path);
  reader->Update();
  const MeshType * mesh = reader->GetOutput();
  double           mean = 0.0;
  double           maximum = 0.0;
  Phantom(options).MeasureDistance(mesh, mean, maximum);
  size_t triangles = 0;
  for (auto it = mesh->GetCells()->Begin(); it != mesh->GetCells()->End(); ++it)
  {
    triangles += it.Value()->GetNumberOfPoints() == 3 ? 1 : 0;
  }
  const double maxMean = Numbers(options, "--max-mean", 1)[0];
  const double maxMax = Numbers(options, "--max-max", 1)[0];
  const double minPoints = options.count("--min-points") ? std::stod(options.at("--min-points")) : 1.0;
  std::cout << path << ": " << mesh->GetNumberOfPoints() << " points, " << triangles
            << " triangles; distance to the ellipsoid: mean " << mean << " mm, max " << maximum << " mm (limits "
            << maxMean << ", " << maxMax << ")" << std::endl;
  const bool good = mean <= maxMean && maximum <= maxMax && mesh->GetNumberOfPoints() >= minPoints && triangles > 0;
  return good ? EXIT_SUCCESS : EXIT_FAILURE;
}

void
WriteSphere(const std::string & path, const std::map<std::string, std::string> & options)
{
  const auto          c = Numbers(options, "--center", 3);
  MeshType::PointType center;
  for (unsigned int k = 0; k < 3; ++k)
  {
    center[k] = c[k];
  }
  const unsigned int resolution =
    options.count("--resolution") ? static_cast<unsigned int>(std::stoi(options.at("--resolution"))) : 3;
  auto mesh = itk::MakeSphereMesh<MeshType>(center, Numbers(options, "--radius", 1)[0], resolution);
  auto writer = itk::MeshFileWriter<MeshType>::New();
  writer->SetInput(mesh);
  writer->SetFileName(path);
  writer->Update();
}

void
WriteLines(const std::string & path)
{
  auto mesh = MeshType::New();
  for (unsigned int i = 0; i < 4; ++i)
  {
    MeshType::PointType p;
    p[0] = 10.0 + i;
    p[1] = 10.0;
    p[2] = 10.0 + 0.5 * i;
    mesh->SetPoint(i, p);
  }
  using CellAutoPointer = MeshType::CellType::CellAutoPointer;
  using LineType = itk::LineCell<MeshType::CellType>;
  for (unsigned int i = 0; i + 1 < 4; ++i)
  {
    CellAutoPointer cell;
    cell.TakeOwnership(new LineType);
    cell->SetPointId(0, i);
    cell->SetPointId(1, i + 1);
    mesh->SetCell(i, cell);
  }
  auto writer = itk::MeshFileWriter<MeshType>::New();
  writer->SetInput(mesh);
  writer->SetFileName(path);
  writer->Update();
}

void
WriteFlat(const std::string & path)
{
  using ImageType = itk::Image<unsigned char, 2>;
  ImageType::SizeType size;
  size.Fill(32);
  auto image = ImageType::New();
  image->SetRegions(size);
  image->Allocate();
  image->FillBuffer(100);
  auto writer = itk::ImageFileWriter<ImageType>::New();
  writer->SetInput(image);
  writer->SetFileName(path);
  writer->Update();
}

} // namespace

int
main(int argc, char * argv[])
{
  if (argc < 3)
  {
    std::cerr << "usage: edmodelTestTool phantom|sphere|lines|flat|measure PATH [--name value]..." << std::endl;
    return EXIT_FAILURE;
  }
  const std::string                  command = argv[1];
  const std::string                  path = argv[2];
  std::map<std::string, std::string> options;
  for (int i = 3; i + 1 < argc; i += 2)
  {
    options[argv[i]] = argv[i + 1];
  }
  try
  {
    if (command == "phantom")
    {
      const std::string pixel = options.count("--pixel") ? options.at("--pixel") : "float";
      if (pixel == "short")
      {
        WritePhantom<short>(path, options);
      }
      else if (pixel == "double")
      {
        WritePhantom<double>(path, options);
      }
      else
      {
        WritePhantom<float>(path, options);
      }
      return EXIT_SUCCESS;
    }
    if (command == "dicom")
    {
      WriteDicomSeries(path, options);
      return EXIT_SUCCESS;
    }
    if (command == "sphere")
    {
      WriteSphere(path, options);
      return EXIT_SUCCESS;
    }
    if (command == "lines")
    {
      WriteLines(path);
      return EXIT_SUCCESS;
    }
    if (command == "flat")
    {
      WriteFlat(path);
      return EXIT_SUCCESS;
    }
    if (command == "measure")
    {
      return Measure(path, options);
    }
  }
  catch (const std::exception & error)
  {
    std::cerr << "edmodelTestTool: " << error.what() << std::endl;
    return EXIT_FAILURE;
  }
  std::cerr << "edmodelTestTool: unknown command " << command << std::endl;
  return EXIT_FAILURE;
}
