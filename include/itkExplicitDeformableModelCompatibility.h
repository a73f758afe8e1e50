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
#ifndef itkExplicitDeformableModelCompatibility_h
#define itkExplicitDeformableModelCompatibility_h

/** \file itkExplicitDeformableModelCompatibility.h
 * \brief The spellings of ITK 5.4 and 6 for ITK 5.2 and 5.3.
 *
 * The module is written with ITK 5.4's macros, which ITK 6 keeps while it
 * removes their older forms (itkTypeMacro; ITKv5_CONST is written const, as
 * in every ITK 5 and 6). On an older ITK this header defines them as ITK 5.4
 * does.
 *
 * \ingroup ExplicitDeformableModel
 */

#include "itkMacro.h"

#ifndef itkOverrideGetNameOfClassMacro
/** ITK 5.4's replacement of itkTypeMacro(thisClass, superclass). */
#  define itkOverrideGetNameOfClassMacro(thisClass)                                                                    \
    const char * GetNameOfClass() const override                                                                       \
    {                                                                                                                  \
      return #thisClass;                                                                                               \
    }                                                                                                                  \
    ITK_MACROEND_NOOP_STATEMENT
#endif

#ifndef itkVirtualGetNameOfClassMacro
/** ITK 5.4's replacement of itkTypeMacroNoParent(thisClass). */
#  define itkVirtualGetNameOfClassMacro(thisClass)                                                                     \
    virtual const char * GetNameOfClass() const                                                                        \
    {                                                                                                                  \
      return #thisClass;                                                                                               \
    }                                                                                                                  \
    ITK_MACROEND_NOOP_STATEMENT
#endif

#endif
