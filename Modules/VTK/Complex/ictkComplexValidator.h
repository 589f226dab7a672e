// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class ictkComplexValidator
 * @brief Checks the relations of an implicit complex against its geometry; the report is a table.
 *
 * Input: the output of ictkComplexSource (or ictkDynamicComplexSource), which carries the complex
 * (ictkComplexSource::COMPLEX()). The complex is discretised at FeatureSize and every declared
 * boundary (Rb) and containment (Rc) pair is checked (ictk::complex::validateComplex), as
 * `ictk validate` does. Output: a vtkTable with one row per finding and the columns Status
 * ("satisfied", "violated", "undeclared"), Relation ("boundary", "containment"), First and
 * Second (the cells' names), Deviation (the largest distance of a sample of Second from the set
 * it must lie on), Witness (the point where it is reached) and Reason; the field data Valid is 1
 * when no declared pair is violated, and Tolerance is the distance used.
 *
 * Errors (no complex on the input, a cell that cannot be discretised) are reported with
 * vtkErrorMacro and the request fails; AbortExecute cancels and leaves an empty table.
 */
#pragma once

#include "ictkFiltersComplexModule.h" // export macro
#include "vtkTableAlgorithm.h"

class ICTKFILTERSCOMPLEX_EXPORT ictkComplexValidator : public vtkTableAlgorithm
{
public:
  static ictkComplexValidator* New();
  vtkTypeMacro(ictkComplexValidator, vtkTableAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Mesh edge length of the discretisation that is sampled; 0 (default) = 1/64 of the complex.
  vtkSetClampMacro(FeatureSize, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(FeatureSize, double);
  /// Distance within which a point counts as on a set; 0 (default) = a quarter of FeatureSize.
  vtkSetClampMacro(Tolerance, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(Tolerance, double);
  /// Also report pairs that hold geometrically but are not declared (default on).
  vtkSetMacro(FindUndeclared, bool);
  vtkGetMacro(FindUndeclared, bool);
  vtkBooleanMacro(FindUndeclared, bool);
  vtkSetClampMacro(NumberOfThreads, int, 0, 1024);
  vtkGetMacro(NumberOfThreads, int);

protected:
  ictkComplexValidator();
  ~ictkComplexValidator() override = default;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  double FeatureSize = 0;
  double Tolerance = 0;
  bool FindUndeclared = true;
  int NumberOfThreads = 0;

private:
  ictkComplexValidator(const ictkComplexValidator&) = delete;
  void operator=(const ictkComplexValidator&) = delete;
};
