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

// One truth per parameter: the defaults of the ITK filters (the reference),
// of the VTK classes, of the ParaView plugin's XML and of `edmodel segment
// --help` agree. A new parameter is one line in a table below.

#include "itkDeformableMeshFilter.h"
#include "itkExternalForceImageFilter.h"
#include "vtkDeformableMesh.h"
#include "vtkExternalForceField.h"
#include "vtkNew.h"

#include "gtest/gtest.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace
{
using ImageType = itk::Image<float, 3>;
using ForceImageType = itk::Image<itk::CovariantVector<float, 3>, 3>;
using MeshType = itk::Mesh<float, 3>;

/** One parameter in every layer. cliDefault: what `edmodel segment --help`
 * states as its default, or nullptr when it is the ITK default (the CLI picks
 * its own defaults for real images where it says so). */
struct Parameter
{
  const char * name; // the ITK, VTK and ParaView name
  double       itk;
  double       vtk;
  const char * cliOption;
  const char * cliDefault;
};

std::string
ReadFile(const std::string & path)
{
  std::ifstream      file(path);
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

std::string
RunProgram(const std::string & command)
{
  std::string output;
  if (FILE * pipe = popen(command.c_str(), "r"))
  {
    char   buffer[4096];
    size_t n;
    while ((n = fread(buffer, 1, sizeof(buffer), pipe)) > 0)
    {
      output.append(buffer, n);
    }
    pclose(pipe);
  }
  return output;
}

/** default_values of the property \a name inside the proxy \a proxy of the
 * plugin's XML; empty when either is missing. */
std::string
XMLDefault(const std::string & xml, const std::string & proxy, const std::string & name)
{
  const auto proxyStart = xml.find("name=\"" + proxy + "\"");
  if (proxyStart == std::string::npos)
  {
    return "";
  }
  const auto proxyEnd = xml.find("</SourceProxy>", proxyStart);
  const auto property = xml.find("Property name=\"" + name + "\"", proxyStart);
  if (property == std::string::npos || property > proxyEnd)
  {
    return "";
  }
  const std::string key = "default_values=\"";
  const auto        value = xml.find(key, property);
  if (value == std::string::npos || value > xml.find('>', property))
  {
    return "";
  }
  return xml.substr(value + key.size(), xml.find('"', value + key.size()) - value - key.size());
}

/** The text of "[default: ...]" in the description of \a option in a --help
 * output (the option begins a line; its description may span lines). */
std::string
HelpDefault(const std::string & help, const std::string & option)
{
  // The option, then its argument or, when it is too long for its column,
  // the end of its line.
  auto start = help.find("\n  " + option + " ");
  start = std::min(start, help.find("\n  " + option + "\n"));
  if (start == std::string::npos)
  {
    return "";
  }
  // The description ends where the next option or section begins.
  auto end = help.find("\n  -", start + 1);
  end = std::min(end, help.find("\n\n", start + 1));
  std::string description = help.substr(start, end - start);
  for (auto p = description.find("\n"); p != std::string::npos; p = description.find("\n"))
  {
    description.replace(p, 1, " ");
  }
  for (auto p = description.find("  "); p != std::string::npos; p = description.find("  "))
  {
    description.erase(p, 1);
  }
  const std::string key = "[default: ";
  const auto        value = description.find(key);
  if (value == std::string::npos)
  {
    return "";
  }
  return description.substr(value + key.size(), description.find(']', value) - value - key.size());
}

/** True when \a text is the number \a value. */
bool
SameNumber(const std::string & text, double value)
{
  char *       end = nullptr;
  const double parsed = std::strtod(text.c_str(), &end);
  return !text.empty() && end != text.c_str() && *end == '\0' && parsed == value;
}

void
CheckLayers(const Parameter *   parameters,
            std::size_t         count,
            const char *        proxy,
            const std::string & xml,
            const std::string & help)
{
  for (std::size_t k = 0; k < count; ++k)
  {
    const Parameter & p = parameters[k];
    EXPECT_EQ(p.vtk, p.itk) << p.name << ": VTK against ITK";
    const std::string xmlDefault = XMLDefault(xml, proxy, p.name);
    EXPECT_TRUE(SameNumber(xmlDefault, p.itk))
      << p.name << ": ParaView XML default_values \"" << xmlDefault << "\", ITK " << p.itk;
    if (p.cliOption != nullptr)
    {
      const std::string cliDefault = HelpDefault(help, p.cliOption);
      if (p.cliDefault != nullptr)
      {
        EXPECT_EQ(cliDefault, p.cliDefault) << p.name << ": edmodel segment " << p.cliOption;
      }
      else
      {
        EXPECT_TRUE(SameNumber(cliDefault, p.itk))
          << p.name << ": edmodel segment " << p.cliOption << " [default: " << cliDefault << "], ITK " << p.itk;
      }
    }
  }
}
} // namespace

TEST(ParameterDefaults, AgreeInTheITKAndVTKClassesThePluginAndTheCommandLine)
{
  const std::string xml = ReadFile(EDM_PLUGIN_XML);
  ASSERT_NE(xml.find("<ServerManagerConfiguration>"), std::string::npos) << EDM_PLUGIN_XML;
  const std::string help = RunProgram(std::string("\"") + EDM_EDMODEL_PROGRAM + "\" segment --help 2>&1");
  ASSERT_NE(help.find("--scale"), std::string::npos) << help;

  const auto                itkModel = itk::DeformableMeshFilter<MeshType, ForceImageType>::New();
  vtkNew<vtkDeformableMesh> vtkModel;
  const Parameter           model[] = {
              // name, ITK, VTK, edmodel option, edmodel's own default (nullptr: ITK's)
    { "ScaleFactor", itkModel->GetScaleFactor(), vtkModel->GetScaleFactor(), "--scale", "0.5 x sigma" },
    { "Elasticity", itkModel->GetElasticity(), vtkModel->GetElasticity(), "--elasticity", "0.3" },
    { "TangentialElasticity",
                static_cast<double>(itkModel->GetTangentialElasticity()),
                static_cast<double>(vtkModel->GetTangentialElasticity()),
                "--no-tangential-elasticity",
                "full umbrella on 3-D surfaces, tangential on 2-D contours" },
    { "Rigidity", itkModel->GetRigidity(), vtkModel->GetRigidity(), "--rigidity", "0.05" },
    { "RegionWeight",
                itkModel->GetRegionWeight(),
                vtkModel->GetRegionWeight(),
                "--region",
                "0.25 x the smallest voxel spacing" },
    { "RegionSigma",
                itkModel->GetRegionSigma(),
                vtkModel->GetRegionSigma(),
                "--region-sigma",
                "1 x the smallest voxel spacing" },
    { "EdgeSearchWeight",
                itkModel->GetEdgeSearchWeight(),
                vtkModel->GetEdgeSearchWeight(),
                "--edge-search",
                "0 x the smallest voxel spacing" },
    { "EdgeSearchDistance",
                itkModel->GetEdgeSearchDistance(),
                vtkModel->GetEdgeSearchDistance(),
                "--edge-search-distance",
                "2 x the smallest voxel spacing" },
    { "IntensityTolerance",
                itkModel->GetIntensityTolerance(),
                vtkModel->GetIntensityTolerance(),
                "--intensity-tolerance",
                nullptr },
    { "EstimateBackgroundIntensity",
                static_cast<double>(itkModel->GetEstimateBackgroundIntensity()),
                static_cast<double>(vtkModel->GetEstimateBackgroundIntensity()),
                nullptr,
                nullptr },
    { "BackgroundUpdateInterval",
                static_cast<double>(itkModel->GetBackgroundUpdateInterval()),
                static_cast<double>(vtkModel->GetBackgroundUpdateInterval()),
                nullptr,
                nullptr },
    { "EstimateObjectIntensityRange",
                static_cast<double>(itkModel->GetEstimateObjectIntensityRange()),
                static_cast<double>(vtkModel->GetEstimateObjectIntensityRange()),
                "--object-range",
                "estimated inside the initial surface" },
    { "EdgePolarity",
                static_cast<double>(itkModel->GetEdgePolarity()),
                static_cast<double>(vtkModel->GetEdgePolarity()),
                nullptr,
                nullptr },
    { "Balloon", itkModel->GetBalloon(), vtkModel->GetBalloon(), "--balloon", nullptr },
    { "MaximumStepLength", itkModel->GetMaximumStepLength(), vtkModel->GetMaximumStepLength(), "--max-step", nullptr },
    { "RemeshingEdgeLength", itkModel->GetRemeshingEdgeLength(), vtkModel->GetRemeshingEdgeLength(), nullptr, nullptr },
    { "RemeshingInterval",
                static_cast<double>(itkModel->GetRemeshingInterval()),
                static_cast<double>(vtkModel->GetRemeshingInterval()),
                nullptr,
                nullptr },
    { "TangentialDrift",
                static_cast<double>(itkModel->GetTangentialDrift()),
                static_cast<double>(vtkModel->GetTangentialDrift()),
                nullptr,
                nullptr },
    { "ReferenceEdgeLength", itkModel->GetReferenceEdgeLength(), vtkModel->GetReferenceEdgeLength(), nullptr, nullptr },
    { "ConvergenceAlongNormals",
                static_cast<double>(itkModel->GetConvergenceAlongNormals()),
                static_cast<double>(vtkModel->GetConvergenceAlongNormals()),
                nullptr,
                nullptr },
    { "PreventSelfIntersections",
                static_cast<double>(itkModel->GetPreventSelfIntersections()),
                static_cast<double>(vtkModel->GetPreventSelfIntersections()),
                "--prevent-self-intersections",
                "on for 3-D surfaces (not used on 2-D contours)" },
    { "MinimumDistance",
                itkModel->GetMinimumDistance(),
                vtkModel->GetMinimumDistance(),
                "--minimum-distance",
                "0.05 x --edge-length" },
    { "FixedBoundary",
                static_cast<double>(itkModel->GetFixedBoundary()),
                static_cast<double>(vtkModel->GetFixedBoundary()),
                nullptr,
                nullptr },
    { "ConvergenceTolerance",
                itkModel->GetConvergenceTolerance(),
                vtkModel->GetConvergenceTolerance(),
                "--tolerance",
                "0.02" },
    { "ConvergenceWindow",
                static_cast<double>(itkModel->GetConvergenceWindow()),
                static_cast<double>(vtkModel->GetConvergenceWindow()),
                "--window",
                nullptr },
    { "ConvergenceFraction",
                itkModel->GetConvergenceFraction(),
                vtkModel->GetConvergenceFraction(),
                "--active-fraction",
                "0.005" },
    { "DampOscillations",
                static_cast<double>(itkModel->GetDampOscillations()),
                static_cast<double>(vtkModel->GetDampOscillations()),
                "--no-damping",
                "damping on" },
  };
  CheckLayers(model, sizeof(model) / sizeof(model[0]), "EDMDeformableMesh", xml, help);

  const auto                    itkForces = itk::ExternalForceImageFilter<ImageType, ForceImageType>::New();
  vtkNew<vtkExternalForceField> vtkForces;
  const Parameter               forces[] = {
                  { "Sigma", itkForces->GetSigma(), vtkForces->GetSigma(), "--sigma", "1 x the smallest voxel spacing" },
                  { "NormalizeForces",
                    static_cast<double>(itkForces->GetNormalizeForces()),
                    static_cast<double>(vtkForces->GetNormalizeForces()),
                    "--no-normalize-forces",
                    "normalised" },
                  { "UseGradientVectorFlow",
                    static_cast<double>(itkForces->GetUseGradientVectorFlow()),
                    static_cast<double>(vtkForces->GetUseGradientVectorFlow()),
                    "--gvf",
                    "off" },
                  { "GradientVectorFlowRegularization",
                    itkForces->GetGradientVectorFlowRegularization(),
                    vtkForces->GetGradientVectorFlowRegularization(),
                    "--gvf-mu",
                    nullptr },
                  { "GradientVectorFlowIterations",
                    static_cast<double>(itkForces->GetGradientVectorFlowIterations()),
                    static_cast<double>(vtkForces->GetGradientVectorFlowIterations()),
                    "--gvf-iterations",
                    nullptr },
  };
  CheckLayers(forces, sizeof(forces) / sizeof(forces[0]), "EDMForceField", xml, help);
}

// The checks above fail when a layer disagrees: a wrong default in the XML
// text or in the help text is seen.
TEST(ParameterDefaults, TheChecksSeeADisagreement)
{
  const std::string xml = "<SourceProxy name=\"P\"><DoubleVectorProperty name=\"A\" command=\"SetA\"\n"
                          "  number_of_elements=\"1\" default_values=\"0.5\"></DoubleVectorProperty></SourceProxy>";
  EXPECT_EQ(XMLDefault(xml, "P", "A"), "0.5");
  EXPECT_FALSE(SameNumber(XMLDefault(xml, "P", "A"), 0.4));
  EXPECT_EQ(XMLDefault(xml, "P", "B"), "");
  const std::string help = "Options:\n  --a MM                      the a, physical units (mm), a long text\n"
                           "                              [default: 0.25]\n  --b N  the b [default: 3]\n";
  EXPECT_EQ(HelpDefault(help, "--a"), "0.25");
  EXPECT_EQ(HelpDefault(help, "--b"), "3");
  EXPECT_EQ(HelpDefault(help, "--c"), "");
}
