// The web viewer's files, embedded into the binary at build time (viewer/embed_viewer.cmake):
// the HTML template viewer/src/viewer.html and viewer/src/viewer.js bundled with three.js
// (the version pinned by viewer/package-lock.json) by esbuild into one script.
#pragma once

#include <string_view>

namespace subflow::output {

std::string_view ViewerTemplate();  // contains /*SUBFLOW_DATA*/ and /*SUBFLOW_BUNDLE*/
std::string_view ViewerBundle();    // "" when the build had no viewer/node_modules
bool ViewerAvailable();             // whether ViewerBundle() holds the viewer

}  // namespace subflow::output
