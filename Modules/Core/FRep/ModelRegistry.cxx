// SPDX-License-Identifier: BSD-3-Clause
#include "FRep/ModelRegistry.h"

#include "FRep/BundledModels.h"

#include <map>
#include <mutex>
#include <stdexcept>

namespace ictk::frep
{

namespace
{
struct Registry
{
  std::mutex mutex;
  // std::map: references returned by findModel stay valid while other models are added.
  std::map<std::string, ModelInfo> models;
};

void checkInfo(const ModelInfo& info);

// The registry starts with the bundled models, so that every user of a name sees them and a
// user model can never shadow one.
Registry& registry()
{
  static Registry* r = []
  {
    auto* created = new Registry;
    for (ModelInfo& info : bundled::modelInfos())
    {
      checkInfo(info);
      std::string name = info.name;
      created->models.emplace(std::move(name), std::move(info));
    }
    return created;
  }();
  return *r;
}

void checkInfo(const ModelInfo& info)
{
  if (info.name.empty())
  {
    throw std::invalid_argument("registerModel: a model needs a name");
  }
  if (!info.build)
  {
    throw std::invalid_argument("registerModel: model '" + info.name + "' has no build function");
  }
  for (int a = 0; a < 3; ++a)
  {
    if (!(info.boundsLo[a] <= info.boundsHi[a]))
    {
      throw std::invalid_argument("registerModel: model '" + info.name + "' has empty bounds");
    }
  }
}

std::string knownNames(const Registry& r)
{
  std::string names;
  for (const auto& entry : r.models)
  {
    names += (names.empty() ? "" : ", ") + entry.first;
  }
  return names;
}
} // namespace

void registerModel(ModelInfo info)
{
  checkInfo(info);
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  if (r.models.count(info.name))
  {
    throw std::invalid_argument(
      "registerModel: a model named '" + info.name + "' is already registered");
  }
  std::string name = info.name;
  r.models.emplace(std::move(name), std::move(info));
}

const ModelInfo& findModel(const std::string& name)
{
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  const auto it = r.models.find(name);
  if (it == r.models.end())
  {
    throw std::invalid_argument("unknown model '" + name + "'; known models: " + knownNames(r));
  }
  return it->second;
}

std::vector<std::string> modelNames()
{
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  std::vector<std::string> names;
  names.reserve(r.models.size());
  for (const auto& entry : r.models)
  {
    names.push_back(entry.first);
  }
  return names;
}

} // namespace ictk::frep
