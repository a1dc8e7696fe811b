#include "vtkGraupelLook.h"

#include "vtkLogger.h"
#include "vtkSMSettings.h"
#include "vtkSMTransferFunctionPresets.h"

#include <string>
#include <vtksys/SystemTools.hxx>

#if defined(__unix__) || defined(__APPLE__)
#include <dlfcn.h>
#define GRAUPEL_HAVE_DLFCN 1
#endif

namespace {
// Below the site's settings (priority 0.5?) and the user's (1.0): a user's
// own default for one of these arrays wins.
const double SettingsPriority = 0.1;

// Dry ground under the water maps: a sand-olive close to the terrain map's
// middle, so that a wet valley is blue in a landscape that is not.
const char *const Settings = R"json({
  "standard_presets": {
    "elevation": "Graupel Terrain",
    "water_depth": "Graupel Water Depth",
    "water_depth_display": "Graupel Water Depth",
    "max_depth": "Graupel Water Depth",
    "snow_depth": "Graupel Snow Depth",
    "snow_density": "Graupel Snow Density",
    "cover_class": "Graupel Cover Classes",
    "shadow": "Graupel Shadow"
  },
  "array_lookup_tables": {
    "water_depth": {"PVLookupTable": {"UseLogScale": 1, "AutomaticRescaleRangeMode": -1,
      "UseBelowRangeColor": 1, "BelowRangeColor": [0.64, 0.60, 0.47]}},
    "water_depth_display": {"PVLookupTable": {"UseLogScale": 1, "AutomaticRescaleRangeMode": -1,
      "UseBelowRangeColor": 1, "BelowRangeColor": [0.64, 0.60, 0.47],
      "NanColor": [0.64, 0.60, 0.47]}},
    "max_depth": {"PVLookupTable": {"UseLogScale": 1, "AutomaticRescaleRangeMode": -1,
      "UseBelowRangeColor": 1, "BelowRangeColor": [0.64, 0.60, 0.47]}},
    "snow_depth": {"PVLookupTable": {"AutomaticRescaleRangeMode": -1,
      "UseBelowRangeColor": 1, "BelowRangeColor": [0.42, 0.31, 0.21]}},
    "snow_density": {"PVLookupTable": {"AutomaticRescaleRangeMode": -1}},
    "cover_class": {"PVLookupTable": {"InterpretValuesAsCategories": 1,
      "AutomaticRescaleRangeMode": -1}},
    "shadow": {"PVLookupTable": {"AutomaticRescaleRangeMode": -1}}
  }
})json";

std::string PresetsFile() {
#if defined(GRAUPEL_HAVE_DLFCN)
  Dl_info self;
  if (dladdr(reinterpret_cast<void *>(&graupel_plugin_load_look), &self) && self.dli_fname) {
    std::string path = self.dli_fname;
    return path.substr(0, path.find_last_of('/') + 1) + "GraupelColorMaps.json";
  }
#endif
  return std::string();
}
} // namespace

void graupel_plugin_load_look() {
  static bool loaded = false;
  if (loaded) {
    return;
  }
  loaded = true;
  vtkSMSettings::GetInstance()->AddCollectionFromString(Settings, SettingsPriority);

  const std::string file = PresetsFile();
  if (file.empty() || !vtksys::SystemTools::FileExists(file)) {
    vtkLog(WARNING, "Graupel: no colour maps at '" << file
                                                   << "'; install GraupelColorMaps.json next to "
                                                      "the plugin.");
    return;
  }
  // ImportPresets renames a preset whose name exists ("Graupel Terrain (1)"),
  // and imported presets are saved in the user's settings: drop the copies an
  // earlier session saved so the names stay the plugin's.
  vtkSMTransferFunctionPresets *presets = vtkSMTransferFunctionPresets::GetInstance();
  for (unsigned int i = presets->GetNumberOfPresets(); i-- > 0;) {
    const std::string name = presets->GetPresetName(i);
    if (name.rfind("Graupel ", 0) == 0 && !presets->IsPresetBuiltin(i)) {
      presets->RemovePreset(i);
    }
  }
  presets->ImportPresets(file.c_str());
}
