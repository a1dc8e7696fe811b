/**
 * Graupel's colour maps, loaded when the plugin loads (every process: the GUI,
 * pvpython, pvbatch):
 * - the presets of GraupelColorMaps.json (next to the plugin) are imported
 *   into ParaView's presets, replacing any of the same name an earlier
 *   session saved, so that scripts can ApplyPreset("Graupel Terrain") and
 *   the GUI lists them;
 * - a settings collection, below the user's and the site's settings (a
 *   user's own "save as default" for an array wins), makes them the defaults
 *   of the arrays they are for: ParaView's transfer-function manager applies
 *   `.standard_presets.<array>` and then `.array_lookup_tables.<array>` to
 *   every new colour map of that array (vtkSMTransferFunctionManager, 5.11).
 *   water_depth and max_depth keep their log range 1 cm - 2 m (dry ground in
 *   the below-range colour), snow arrays their fixed ranges; elevation is
 *   rescaled to the data as usual.
 */
#ifndef vtkGraupelLook_h
#define vtkGraupelLook_h

void graupel_plugin_load_look();

#endif
