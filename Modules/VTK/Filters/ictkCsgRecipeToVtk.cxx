// SPDX-License-Identifier: BSD-3-Clause
#include "ictkCsgRecipeToVtk.h"

#include "vtkBox.h"
#include "vtkCylinder.h"
#include "vtkImplicitBoolean.h"
#include "vtkSphere.h"

#include <stdexcept>

namespace
{
using ictk::frep::bundled::CsgNode;
using ictk::frep::bundled::CsgRecipe;

vtkSmartPointer<vtkImplicitFunction> node(const CsgRecipe& r, int index)
{
  const CsgNode& n = r.nodes.at(static_cast<std::size_t>(index));
  switch (n.kind)
  {
    case CsgNode::Kind::Sphere:
    {
      auto s = vtkSmartPointer<vtkSphere>::New();
      s->SetCenter(n.p[0], n.p[1], n.p[2]);
      s->SetRadius(n.p[3]);
      return s;
    }
    case CsgNode::Kind::Box:
    {
      auto b = vtkSmartPointer<vtkBox>::New();
      b->SetBounds(n.p[0], n.p[3], n.p[1], n.p[4], n.p[2], n.p[5]);
      return b;
    }
    case CsgNode::Kind::CylinderY:
    {
      auto c = vtkSmartPointer<vtkCylinder>::New();
      c->SetCenter(n.p[0], n.p[1], n.p[2]);
      c->SetRadius(n.p[3]);
      c->SetAxis(0, 1, 0);
      return c;
    }
    case CsgNode::Kind::Union:
    case CsgNode::Kind::Intersection:
    case CsgNode::Kind::Difference:
    {
      auto op = vtkSmartPointer<vtkImplicitBoolean>::New();
      if (n.kind == CsgNode::Kind::Union)
      {
        op->SetOperationTypeToUnion();
      }
      else if (n.kind == CsgNode::Kind::Intersection)
      {
        op->SetOperationTypeToIntersection();
      }
      else
      {
        op->SetOperationTypeToDifference();
      }
      op->AddFunction(node(r, n.a));
      op->AddFunction(node(r, n.b));
      return op;
    }
  }
  throw std::invalid_argument("ictkCsgRecipeToVtk: unknown node kind");
}
} // namespace

vtkSmartPointer<vtkImplicitFunction> ictkCsgRecipeToVtk(const CsgRecipe& recipe)
{
  return node(recipe, recipe.root);
}
