
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
//   edmodelTestTool ellipse2d IMG --size X,Y --spacing X,Y --origin X,Y --center X,Y --radii A,B
//                   [--angle RAD] [--inside V] [--outside V] [--pixel uchar|float] [--slab 1]
//                   [--holes X1,Y1,R1,X2,Y2,R2,...]
//                   (anti-aliased 2-D ellipse, the a-axis at RAD from x; --slab: a volume of one slice;
//                   --holes: disks of the outside value inside it)
//   edmodelTestTool measure-contour CONTOUR(.csv|.vtk) --center X,Y --radii A,B [--angle RAD]
//                   --max-mean D --max-max D [--min-points N]
//                   (also fails when two edges of the closed contour that share no point cross)
//   edmodelTestTool contour-csv CSV --points X1,Y1,X2,Y2,...   (one contour, x,y per line)
//   edmodelTestTool check-ends CONTOUR(.csv|.vtk) --first X,Y --last X,Y   (exactly these ends)
//   edmodelTestTool check-overlay PNG --min-size N --min-red N
//                   (an RGB PNG at least N pixels across, with at least N red contour pixels)
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
#include "itkImageFileReader.h"
#include "itkImageRegionIteratorWithIndex.h"
#include "itkMetaDataObject.h"
#include "itkRGBPixel.h"

#include <cmath>
#include <cstdlib>
#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
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
  const double radius = Numbers(options, "--radius", 1)[0];
  auto         mesh = itk::MakeSphereMesh<MeshType>(center, radius, resolution);
  if (options.count("--fold"))
  {
    // Point 0 pushed through the sphere to 1.5 radii beyond the centre on
    // the other side: its triangles cross those around the antipode, a
    // surface that intersects itself.
    const auto p = mesh->GetPoint(0);
    auto       q = p;
    for (unsigned int k = 0; k < 3; ++k)
    {
      q[k] = center[k] - 1.5 * (p[k] - center[k]);
    }
    mesh->SetPoint(0, q);
  }
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

// --- 2-D ----------------------------------------------------------------------

/** Anti-aliased 2-D ellipse: each pixel holds the fraction of its 16 x 16
 * sub-samples inside, between --outside and --inside. */
template <typename TPixel, unsigned int VDimension>
void
WriteEllipse2D(const std::string & path, const std::map<std::string, std::string> & options)
{
  using ImageType = itk::Image<TPixel, VDimension>;
  const auto          size = Numbers(options, "--size", 2);
  const auto          spacing = Numbers(options, "--spacing", 2);
  const auto          origin = Numbers(options, "--origin", 2);
  const auto          c = Numbers(options, "--center", 2);
  const auto          r = Numbers(options, "--radii", 2);
  const double        angle = options.count("--angle") ? std::stod(options.at("--angle")) : 0.0;
  const double        inside = options.count("--inside") ? std::stod(options.at("--inside")) : 200.0;
  const double        outside = options.count("--outside") ? std::stod(options.at("--outside")) : 40.0;
  std::vector<double> holes;
  if (options.count("--holes"))
  {
    std::stringstream list(options.at("--holes"));
    for (std::string item; std::getline(list, item, ',');)
    {
      holes.push_back(std::stod(item));
    }
    if (holes.empty() || holes.size() % 3 != 0)
    {
      throw std::runtime_error("--holes needs X,Y,R triples");
    }
  }
  typename ImageType::SizeType    imageSize;
  typename ImageType::SpacingType imageSpacing;
  typename ImageType::PointType   imageOrigin;
  imageSize.Fill(1);
  imageSpacing.Fill(1.0);
  imageOrigin.Fill(0.0);
  for (unsigned int k = 0; k < 2; ++k)
  {
    imageSize[k] = static_cast<itk::SizeValueType>(size[k]);
    imageSpacing[k] = spacing[k];
    imageOrigin[k] = origin[k];
  }
  auto image = ImageType::New();
  image->SetRegions(imageSize);
  image->SetSpacing(imageSpacing);
  image->SetOrigin(imageOrigin);
  image->Allocate();
  constexpr unsigned int sub = 16;
  for (itk::ImageRegionIteratorWithIndex<ImageType> it(image, image->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    unsigned int count = 0;
    for (unsigned int a = 0; a < sub; ++a)
    {
      for (unsigned int b = 0; b < sub; ++b)
      {
        const double x = origin[0] + (it.GetIndex()[0] - 0.5 + (a + 0.5) / sub) * spacing[0] - c[0];
        const double y = origin[1] + (it.GetIndex()[1] - 0.5 + (b + 0.5) / sub) * spacing[1] - c[1];
        const double u = std::cos(angle) * x + std::sin(angle) * y;
        const double v = -std::sin(angle) * x + std::cos(angle) * y;
        bool         in = (u / r[0]) * (u / r[0]) + (v / r[1]) * (v / r[1]) <= 1.0;
        for (size_t h = 0; h < holes.size() && in; h += 3)
        {
          in = std::hypot(x + c[0] - holes[h], y + c[1] - holes[h + 1]) > holes[h + 2];
        }
        count += in ? 1 : 0;
      }
    }
    const double fraction = static_cast<double>(count) / (sub * sub);
    it.Set(static_cast<TPixel>(std::lround(1000.0 * (outside + (inside - outside) * fraction)) / 1000.0));
  }
  auto writer = itk::ImageFileWriter<ImageType>::New();
  writer->SetInput(image);
  writer->SetFileName(path);
  writer->Update();
}

/** The points of a contour written by edmodel: .csv (x,y lines after a
 * header) or legacy .vtk (its POINTS section). */
std::vector<std::array<double, 2>>
ReadContourPoints(const std::string & path)
{
  std::ifstream                      stream(path);
  std::vector<std::array<double, 2>> points;
  if (!stream)
  {
    throw std::runtime_error("cannot read " + path);
  }
  if (path.size() > 4 && path.compare(path.size() - 4, 4, ".csv") == 0)
  {
    std::string line;
    std::getline(stream, line); // header
    while (std::getline(stream, line))
    {
      if (line.empty())
      {
        continue;
      }
      const auto comma = line.find(',');
      points.push_back({ std::stod(line.substr(0, comma)), std::stod(line.substr(comma + 1)) });
    }
    return points;
  }
  std::string word;
  while (stream >> word && word != "POINTS")
  {}
  size_t n = 0;
  stream >> n >> word;
  for (size_t i = 0; i < n; ++i)
  {
    double x = 0.0;
    double y = 0.0;
    double z = 0.0;
    stream >> x >> y >> z;
    points.push_back({ x, y });
  }
  if (!stream)
  {
    throw std::runtime_error("cannot read the POINTS of " + path);
  }
  return points;
}

/** Mean and largest distance of a contour's points to the ellipse, by dense
 * sampling refined by golden-section search (exact to 1e-9 mm). */
int
MeasureContour(const std::string & path, const std::map<std::string, std::string> & options)
{
  const auto   c = Numbers(options, "--center", 2);
  const auto   r = Numbers(options, "--radii", 2);
  const double angle = options.count("--angle") ? std::stod(options.at("--angle")) : 0.0;
  const auto   curve = [&](double t) {
    const double u = r[0] * std::cos(t);
    const double v = r[1] * std::sin(t);
    return std::array<double, 2>{ c[0] + std::cos(angle) * u - std::sin(angle) * v,
                                  c[1] + std::sin(angle) * u + std::cos(angle) * v };
  };
  const auto distance = [](const std::array<double, 2> & a, const std::array<double, 2> & b) {
    return std::hypot(a[0] - b[0], a[1] - b[1]);
  };
  constexpr unsigned int samples = 20000;
  constexpr double       twoPi = 6.283185307179586;
  const auto             points = ReadContourPoints(path);
  double                 mean = 0.0;
  double                 maximum = 0.0;
  for (const auto & p : points)
  {
    unsigned int best = 0;
    double       bestDistance = 1e300;
    for (unsigned int k = 0; k < samples; ++k)
    {
      const double d = distance(p, curve(twoPi * k / samples));
      if (d < bestDistance)
      {
        bestDistance = d;
        best = k;
      }
    }
    double lo = twoPi * (best - 1.0) / samples;
    double hi = twoPi * (best + 1.0) / samples;
    for (unsigned int step = 0; step < 60; ++step)
    {
      const double m1 = lo + (hi - lo) * 0.381966;
      const double m2 = hi - (hi - lo) * 0.381966;
      if (distance(p, curve(m1)) < distance(p, curve(m2)))
      {
        hi = m2;
      }
      else
      {
        lo = m1;
      }
    }
    const double d = std::min(bestDistance, distance(p, curve(0.5 * (lo + hi))));
    mean += d;
    maximum = std::max(maximum, d);
  }
  mean /= std::max<size_t>(1, points.size());
  // Edges of the closed contour that share no point and cross (or touch):
  // all pairs, independently of edmodel's own test.
  const size_t n = points.size();
  size_t       crossings = 0;
  const auto   cross =
    [](const std::array<double, 2> & o, const std::array<double, 2> & a, const std::array<double, 2> & b) {
      return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
    };
  for (size_t k = 0; k < n && n >= 4; ++k)
  {
    for (size_t m = k + 2; m < n; ++m)
    {
      if (k == 0 && m == n - 1)
      {
        continue;
      }
      const auto & a = points[k];
      const auto & b = points[(k + 1) % n];
      const auto & p = points[m];
      const auto & q = points[(m + 1) % n];
      const double d1 = cross(a, b, p);
      const double d2 = cross(a, b, q);
      const double d3 = cross(p, q, a);
      const double d4 = cross(p, q, b);
      if (((d1 <= 0.0 && d2 >= 0.0) || (d1 >= 0.0 && d2 <= 0.0)) &&
          ((d3 <= 0.0 && d4 >= 0.0) || (d3 >= 0.0 && d4 <= 0.0)))
      {
        ++crossings;
      }
    }
  }
  const double maxMean = Numbers(options, "--max-mean", 1)[0];
  const double maxMax = Numbers(options, "--max-max", 1)[0];
  const double minPoints = options.count("--min-points") ? std::stod(options.at("--min-points")) : 3.0;
  std::cout << path << ": " << points.size() << " points; distance to the ellipse: mean " << mean << " mm, max "
            << maximum << " mm (limits " << maxMean << ", " << maxMax << "); " << crossings
            << " pair(s) of crossing edges" << std::endl;
  return mean <= maxMean && maximum <= maxMax && points.size() >= minPoints && crossings == 0 ? EXIT_SUCCESS
                                                                                              : EXIT_FAILURE;
}

int
CheckOverlay(const std::string & path, const std::map<std::string, std::string> & options)
{
  using RGBImageType = itk::Image<itk::RGBPixel<unsigned char>, 2>;
  auto reader = itk::ImageFileReader<RGBImageType>::New();
  reader->SetFileName(path);
  reader->Update();
  const auto * image = reader->GetOutput();
  const auto   size = image->GetLargestPossibleRegion().GetSize();
  size_t       red = 0;
  for (itk::ImageRegionConstIterator<RGBImageType> it(image, image->GetBufferedRegion()); !it.IsAtEnd(); ++it)
  {
    red += it.Get()[0] == 255 && it.Get()[1] == 0 && it.Get()[2] == 0 ? 1 : 0;
  }
  const double minSize = Numbers(options, "--min-size", 1)[0];
  const double minRed = Numbers(options, "--min-red", 1)[0];
  std::cout << path << ": " << size[0] << " x " << size[1] << " pixels, " << red << " red" << std::endl;
  return std::max(size[0], size[1]) >= minSize && red >= minRed ? EXIT_SUCCESS : EXIT_FAILURE;
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
    if (command == "ellipse2d")
    {
      const bool        slab = options.count("--slab") != 0;
      const std::string pixel = options.count("--pixel") ? options.at("--pixel") : "float";
      if (pixel == "uchar")
      {
        slab ? WriteEllipse2D<unsigned char, 3>(path, options) : WriteEllipse2D<unsigned char, 2>(path, options);
      }
      else
      {
        slab ? WriteEllipse2D<float, 3>(path, options) : WriteEllipse2D<float, 2>(path, options);
      }
      return EXIT_SUCCESS;
    }
    if (command == "measure-contour")
    {
      return MeasureContour(path, options);
    }
    if (command == "contour-csv")
    {
      const auto    text = options.at("--points");
      const auto    count = static_cast<size_t>(std::count(text.begin(), text.end(), ',') + 1);
      const auto    values = Numbers(options, "--points", count);
      std::ofstream stream(path);
      stream << "x,y\n";
      for (size_t k = 0; k + 1 < values.size(); k += 2)
      {
        stream << values[k] << "," << values[k + 1] << "\n";
      }
      return stream ? EXIT_SUCCESS : EXIT_FAILURE;
    }
    if (command == "check-ends")
    {
      const auto points = ReadContourPoints(path);
      const auto first = Numbers(options, "--first", 2);
      const auto last = Numbers(options, "--last", 2);
      std::cout << path << ": " << points.size() << " points from (" << points.front()[0] << ", " << points.front()[1]
                << ") to (" << points.back()[0] << ", " << points.back()[1] << ")" << std::endl;
      return points.size() > 2 && points.front()[0] == first[0] && points.front()[1] == first[1] &&
                 points.back()[0] == last[0] && points.back()[1] == last[1]
               ? EXIT_SUCCESS
               : EXIT_FAILURE;
    }
    if (command == "check-overlay")
    {
      return CheckOverlay(path, options);
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
