// SPDX-License-Identifier: BSD-3-Clause
#include "ictkComplexValidator.h"

#include "Complex/Discretization.h"
#include "Complex/Validation.h"
#include "FRep/Sampling.h"
#include "ictkComplexSource.h"
#include "ictkRequest.h"

#include "vtkDataObject.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkStringArray.h"
#include "vtkTable.h"

namespace complex = ictk::complex;

vtkStandardNewMacro(ictkComplexValidator);

ictkComplexValidator::ictkComplexValidator()
{
  this->SetNumberOfInputPorts(1);
}

int ictkComplexValidator::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkDataObject");
  return 1;
}

int ictkComplexValidator::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkTable* output = vtkTable::GetData(outputVector);
  const auto k = ictkComplexSource::GetComplex(vtkDataObject::GetData(inputVector[0]));
  if (!k)
  {
    vtkErrorMacro("the input carries no complex: connect an ictkComplexSource");
    return 0;
  }
  return ictk::vtk::runRequest(this, output,
    [&]
    {
      complex::DiscretizationOptions d;
      d.featureSize = this->FeatureSize;
      d.threads = this->NumberOfThreads;
      d.progress = ictk::vtk::progressOf(this, 0, 0.5);
      const complex::ComplexMesh mesh = complex::discretizeComplex(*k, d);
      complex::ValidationOptions v;
      v.tolerance = this->Tolerance;
      v.findUndeclared = this->FindUndeclared;
      const complex::ValidationReport report = complex::validateComplex(*k, mesh, v);

      vtkNew<vtkStringArray> status, relation, first, second, reason;
      status->SetName("Status");
      relation->SetName("Relation");
      first->SetName("First");
      second->SetName("Second");
      reason->SetName("Reason");
      vtkNew<vtkDoubleArray> deviation, witness;
      deviation->SetName("Deviation");
      witness->SetName("Witness");
      witness->SetNumberOfComponents(3);
      const std::pair<const char*, const std::vector<complex::RelationFinding>*> groups[] = {
        { "violated", &report.violated },
        { "undeclared", &report.undeclared },
        { "satisfied", &report.satisfied },
      };
      for (const auto& [name, findings] : groups)
      {
        for (const complex::RelationFinding& f : *findings)
        {
          status->InsertNextValue(name);
          relation->InsertNextValue(
            f.kind == complex::RelationKind::Boundary ? "boundary" : "containment");
          first->InsertNextValue(k->cell(f.first).name);
          second->InsertNextValue(k->cell(f.second).name);
          deviation->InsertNextValue(f.deviation);
          witness->InsertNextTuple(f.witness.data());
          reason->InsertNextValue(f.reason);
        }
      }
      output->Initialize();
      output->AddColumn(status);
      output->AddColumn(relation);
      output->AddColumn(first);
      output->AddColumn(second);
      output->AddColumn(deviation);
      output->AddColumn(witness);
      output->AddColumn(reason);
      vtkNew<vtkIntArray> valid;
      valid->SetName("Valid");
      valid->InsertNextValue(report.ok() ? 1 : 0);
      output->GetFieldData()->AddArray(valid);
      vtkNew<vtkDoubleArray> tolerance;
      tolerance->SetName("Tolerance");
      tolerance->InsertNextValue(report.tolerance);
      output->GetFieldData()->AddArray(tolerance);
      this->UpdateProgress(1.0);
      return 1;
    });
}

void ictkComplexValidator::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FeatureSize: " << this->FeatureSize << "\n";
  os << indent << "Tolerance: " << this->Tolerance << "\n";
  os << indent << "FindUndeclared: " << this->FindUndeclared << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
}
