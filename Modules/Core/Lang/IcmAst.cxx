// SPDX-License-Identifier: BSD-3-Clause
#include "Lang/IcmAst.h"

namespace ictk::lang::icm
{

const Property* CellDef::property(const std::string& n) const
{
  for (const Property& p : properties)
  {
    if (p.name == n)
    {
      return &p;
    }
  }
  return nullptr;
}

const CellDef* Model::cell(const std::string& n) const
{
  for (const CellsSection& s : cells)
  {
    for (const CellDef& c : s.defs)
    {
      if (c.name.text == n)
      {
        return &c;
      }
    }
  }
  for (const Instance& in : instances)
  {
    for (const CellsSection& s : in.cells)
    {
      for (const CellDef& c : s.defs)
      {
        if (c.name.text == n)
        {
          return &c;
        }
      }
    }
  }
  return nullptr;
}

const Instance* Model::instance(const std::string& n) const
{
  for (const Instance& in : instances)
  {
    if (in.name.text == n)
    {
      return &in;
    }
  }
  return nullptr;
}

const Event* Model::event(const std::string& n) const
{
  for (const Event& e : events)
  {
    if (e.name.text == n)
    {
      return &e;
    }
  }
  return nullptr;
}

const CellDef* Model::animation(const std::string& n) const
{
  for (const CellDef& a : animations)
  {
    if (a.name.text == n)
    {
      return &a;
    }
  }
  return nullptr;
}

} // namespace ictk::lang::icm
