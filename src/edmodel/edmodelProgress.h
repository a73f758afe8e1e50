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
#ifndef edmodelProgress_h
#define edmodelProgress_h

// Progress of edmodel's stages on stderr, shared by the 3-D pipeline
// (edmodelPipeline.cxx) and the 2-D one (edmodelContour.cxx).

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <string>
#include <unistd.h>

namespace edm
{

/** Progress on stderr: a bar redrawn in place on a terminal, a plain line
 * every tenth otherwise, nothing with --quiet. */
class Progress
{
public:
  explicit Progress(bool quiet)
    : m_Enabled(!quiet)
    , m_Terminal(isatty(fileno(stderr)) != 0)
  {}

  void
  Start(const std::string & stage)
  {
    m_Stage = stage;
    m_LastTenth = -1;
    m_LastDraw = std::chrono::steady_clock::time_point();
    m_Drawn = false;
  }

  /** False for a quiet progress (--quiet, the repeated runs of --repeat),
   * which never draws: callers then need not observe what they would show. */
  bool
  IsEnabled() const
  {
    return m_Enabled;
  }

  /** True when Update(fraction, ...) would draw: callers that build their
   * detail text at every iteration ask first (the text costs more than a
   * small contour's iteration). */
  bool
  Due(double fraction) const
  {
    if (!m_Enabled)
    {
      return false;
    }
    fraction = std::min(1.0, std::max(0.0, fraction));
    if (m_Terminal)
    {
      return fraction >= 1.0 || !m_Drawn ||
             std::chrono::steady_clock::now() - m_LastDraw >= std::chrono::milliseconds(100);
    }
    return static_cast<int>(fraction * 10.0 + 1e-9) > m_LastTenth;
  }

  void
  Update(double fraction, const std::string & detail)
  {
    if (!m_Enabled)
    {
      return;
    }
    fraction = std::min(1.0, std::max(0.0, fraction));
    if (m_Terminal)
    {
      const auto now = std::chrono::steady_clock::now();
      if (fraction < 1.0 && m_Drawn && now - m_LastDraw < std::chrono::milliseconds(100))
      {
        return;
      }
      m_LastDraw = now;
      m_Drawn = true;
      constexpr int width = 30;
      const int     filled = static_cast<int>(fraction * width + 0.5);
      std::cerr << "\r\033[K" << m_Stage << " [" << std::string(filled, '#') << std::string(width - filled, '.') << "] "
                << std::setw(3) << static_cast<int>(fraction * 100.0 + 0.5) << "%  " << detail << std::flush;
      return;
    }
    const int tenth = static_cast<int>(fraction * 10.0 + 1e-9);
    if (tenth > m_LastTenth)
    {
      m_LastTenth = tenth;
      std::cerr << "edmodel: " << m_Stage << " " << std::setw(3) << tenth * 10 << "%" << (detail.empty() ? "" : "  ")
                << detail << std::endl;
    }
  }

  /** Ends the stage with a summary line. */
  void
  Finish(const std::string & summary)
  {
    if (!m_Enabled)
    {
      return;
    }
    if (m_Terminal && m_Drawn)
    {
      std::cerr << "\r\033[K";
    }
    std::cerr << "edmodel: " << m_Stage << ": " << summary << std::endl;
  }

  void
  Note(const std::string & text)
  {
    if (m_Enabled)
    {
      std::cerr << "edmodel: " << text << std::endl;
    }
  }

private:
  bool                                  m_Enabled;
  bool                                  m_Terminal;
  std::string                           m_Stage;
  int                                   m_LastTenth{ -1 };
  bool                                  m_Drawn{ false };
  std::chrono::steady_clock::time_point m_LastDraw;
};

} // namespace edm

#endif
