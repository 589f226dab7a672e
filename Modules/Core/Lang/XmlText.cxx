// SPDX-License-Identifier: BSD-3-Clause
#include "Lang/XmlText.h"

#include <stdexcept>

namespace ictk::lang
{

std::string xmlAttribute(const std::string& value, const std::string& what)
{
  std::string s;
  s.reserve(value.size());
  for (char c : value)
  {
    switch (c)
    {
      case '&':
        s += "&amp;";
        break;
      case '<':
        s += "&lt;";
        break;
      case '>':
        s += "&gt;";
        break;
      case '"':
        s += "&quot;";
        break;
      // Character references, because a parser normalises literal white space in attributes.
      case '\n':
        s += "&#10;";
        break;
      case '\r':
        s += "&#13;";
        break;
      case '\t':
        s += "&#9;";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20)
        {
          throw std::invalid_argument(
            what + " contains a control character, which XML 1.0 cannot carry");
        }
        s += c;
    }
  }
  return s;
}

} // namespace ictk::lang
