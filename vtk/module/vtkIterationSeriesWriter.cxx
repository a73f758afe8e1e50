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
#include "vtkIterationSeriesWriter.h"

#include "vtkErrorCode.h"
#include "vtkIterativePolyDataAlgorithm.h"
#include "vtkObjectFactory.h"
#include "vtkPolyData.h"
#include "vtkXMLPolyDataWriter.h"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

vtkStandardNewMacro(vtkIterationSeriesWriter);
vtkCxxSetObjectMacro(vtkIterationSeriesWriter, Algorithm, vtkIterativePolyDataAlgorithm);

/** The files of the collection: (iteration, path). */
class vtkIterationSeriesWriterInternals
{
public:
  std::vector<std::pair<int, std::string>> Files;
};

namespace
{
/** "dir/name.pvd" -> ("dir/", "name"). */
void
SplitFileName(const std::string & fileName, std::string & directory, std::string & stem)
{
  const std::size_t slash = fileName.find_last_of("/\\");
  directory = slash == std::string::npos ? std::string() : fileName.substr(0, slash + 1);
  stem = slash == std::string::npos ? fileName : fileName.substr(slash + 1);
  const std::size_t dot = stem.find_last_of('.');
  if (dot != std::string::npos && dot > 0)
  {
    stem = stem.substr(0, dot);
  }
}

/** Writes \a data to \a path, every call checked; a partial file is removed. */
bool
WriteChecked(const std::string & data, const std::string & path, std::string & problem)
{
  std::FILE * file = std::fopen(path.c_str(), "wb");
  if (file == nullptr)
  {
    problem = std::strerror(errno);
    return false;
  }
  const std::size_t written = std::fwrite(data.data(), 1, data.size(), file);
  int               code = written == data.size() ? 0 : errno;
  if (std::fflush(file) != 0 && code == 0)
  {
    code = errno;
  }
  if (std::fclose(file) != 0 && code == 0)
  {
    code = errno;
  }
  if (code != 0 || written != data.size())
  {
    problem = std::strerror(code != 0 ? code : EIO);
    std::remove(path.c_str());
    return false;
  }
  return true;
}

std::string
EscapeXML(const std::string & text)
{
  std::string escaped;
  for (const char c : text)
  {
    switch (c)
    {
      case '&':
        escaped += "&amp;";
        break;
      case '<':
        escaped += "&lt;";
        break;
      case '>':
        escaped += "&gt;";
        break;
      case '"':
        escaped += "&quot;";
        break;
      default:
        escaped += c;
    }
  }
  return escaped;
}
} // namespace

//------------------------------------------------------------------------------
vtkIterationSeriesWriter::vtkIterationSeriesWriter()
  : Internals(new vtkIterationSeriesWriterInternals)
{}

//------------------------------------------------------------------------------
vtkIterationSeriesWriter::~vtkIterationSeriesWriter()
{
  this->SetFileName(nullptr);
  this->SetAlgorithm(nullptr);
  delete this->Internals;
}

//------------------------------------------------------------------------------
void
vtkIterationSeriesWriter::ClearCollection()
{
  this->Internals->Files.clear();
}

//------------------------------------------------------------------------------
int
vtkIterationSeriesWriter::GetNumberOfWrittenFiles()
{
  return static_cast<int>(this->Internals->Files.size());
}

//------------------------------------------------------------------------------
const char *
vtkIterationSeriesWriter::GetWrittenFileName(int k)
{
  if (k < 0 || k >= this->GetNumberOfWrittenFiles())
  {
    return nullptr;
  }
  return this->Internals->Files[k].second.c_str();
}

//------------------------------------------------------------------------------
int
vtkIterationSeriesWriter::GetWrittenIteration(int k)
{
  if (k < 0 || k >= this->GetNumberOfWrittenFiles())
  {
    return -1;
  }
  return this->Internals->Files[k].first;
}

//------------------------------------------------------------------------------
int
vtkIterationSeriesWriter::WriteIteration(vtkPolyData * mesh, int iteration)
{
  if (this->FileName == nullptr || this->FileName[0] == '\0')
  {
    vtkErrorMacro("No FileName: set the path of the .pvd collection.");
    return 0;
  }
  if (mesh == nullptr)
  {
    vtkErrorMacro("No mesh to write for iteration " << iteration << ".");
    return 0;
  }
  std::string directory;
  std::string stem;
  SplitFileName(this->FileName, directory, stem);
  char number[32];
  std::snprintf(number, sizeof(number), "_%06d.vtp", iteration);
  const std::string path = directory + stem + number;

  // To memory, then to the file with every write checked: VTK's XML writer
  // crashes when the disk fills up under it.
  auto writer = vtkSmartPointer<vtkXMLPolyDataWriter>::New();
  writer->WriteToOutputStringOn();
  writer->SetInputData(mesh);
  if (this->Binary)
  {
    writer->SetDataModeToBinary(); // inline: ParaView 5.11 on Debian 12 cannot parse appended data
  }
  else
  {
    writer->SetDataModeToAscii();
  }
  if (writer->Write() != 1 || writer->GetErrorCode() != vtkErrorCode::NoError)
  {
    vtkErrorMacro("Cannot write " << path << ".");
    return 0;
  }
  std::string problem;
  if (!WriteChecked(writer->GetOutputString(), path, problem))
  {
    vtkErrorMacro("Cannot write " << path << ": " << problem << ".");
    return 0;
  }
  this->Internals->Files.emplace_back(iteration, path);
  return 1;
}

//------------------------------------------------------------------------------
int
vtkIterationSeriesWriter::WriteCollection()
{
  if (this->FileName == nullptr || this->FileName[0] == '\0')
  {
    vtkErrorMacro("No FileName: set the path of the .pvd collection.");
    return 0;
  }
  std::ofstream stream(this->FileName);
  if (!stream)
  {
    vtkErrorMacro("Cannot open " << this->FileName << " for writing.");
    return 0;
  }
  std::string directory;
  std::string stem;
  SplitFileName(this->FileName, directory, stem);
  stream << "<?xml version=\"1.0\"?>\n"
         << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
         << "  <Collection>\n";
  for (const auto & file : this->Internals->Files)
  {
    // The collection refers to its files relative to its own directory.
    std::string relative = file.second;
    if (!directory.empty() && relative.compare(0, directory.size(), directory) == 0)
    {
      relative = relative.substr(directory.size());
    }
    stream << "    <DataSet timestep=\"" << file.first << "\" group=\"\" part=\"0\" file=\"" << EscapeXML(relative)
           << "\"/>\n";
  }
  stream << "  </Collection>\n"
         << "</VTKFile>\n";
  stream.close();
  if (!stream)
  {
    vtkErrorMacro("Cannot write " << this->FileName << ".");
    return 0;
  }
  return 1;
}

//------------------------------------------------------------------------------
int
vtkIterationSeriesWriter::Write()
{
  if (this->Algorithm == nullptr)
  {
    vtkErrorMacro("No algorithm: call SetAlgorithm() before Write().");
    return 0;
  }
  if (this->FileName == nullptr || this->FileName[0] == '\0')
  {
    vtkErrorMacro("No FileName: set the path of the .pvd collection.");
    return 0;
  }
  vtkIterativePolyDataAlgorithm * algorithm = this->Algorithm;
  const vtkTypeBool               iterateFromZero = algorithm->GetIterateFromZero();
  const int                       numberOfIterations = algorithm->GetNumberOfIterations();
  algorithm->IterateFromZeroOff();
  this->ClearCollection();

  int result = 1;
  for (int target = 0;; target = std::min(target + this->Interval, this->NumberOfIterations))
  {
    algorithm->SetNumberOfIterations(target);
    algorithm->Update();
    vtkPolyData * output = algorithm->GetOutput();
    if (output == nullptr || output->GetNumberOfPoints() == 0)
    {
      vtkErrorMacro("The algorithm produced no mesh at iteration " << target << ".");
      result = 0;
      break;
    }
    const int reached = algorithm->GetCurrentIteration();
    if (!this->WriteIteration(output, reached))
    {
      result = 0;
      break;
    }
    if (reached < target || target >= this->NumberOfIterations)
    {
      break;
    }
  }
  if (result)
  {
    result = this->WriteCollection();
  }
  algorithm->SetIterateFromZero(iterateFromZero);
  algorithm->SetNumberOfIterations(numberOfIterations);
  return result;
}

//------------------------------------------------------------------------------
void
vtkIterationSeriesWriter::PrintSelf(ostream & os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "Interval: " << this->Interval << "\n";
  os << indent << "NumberOfIterations: " << this->NumberOfIterations << "\n";
  os << indent << "Binary: " << (this->Binary ? "On" : "Off") << "\n";
  os << indent << "Algorithm: " << static_cast<void *>(this->Algorithm) << "\n";
  os << indent << "WrittenFiles: " << this->Internals->Files.size() << "\n";
}
