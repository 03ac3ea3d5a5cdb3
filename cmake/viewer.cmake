# The HTML viewer's JavaScript: viewer/main.js and three.js bundled by esbuild into one IIFE
# at build time, then embedded into the library as pic::kViewerBundle (src/render/viewer.cpp).
#
# Defines:
#   PIC_GENERATED_DIR       ${CMAKE_BINARY_DIR}/generated
#   PIC_VIEWER_BUNDLE_CPP   the generated source to add to target pic
#   PIC_NODE, PIC_NPM       node and npm, if found
#   pic_npm_ci(TARGET SRC_DIR WORK_DIR)  a target that installs SRC_DIR's locked npm
#                           packages into WORK_DIR/node_modules (used by the tests too)
#
# npm ci runs in a copy of the package files inside the build tree rather than in the source
# tree: two build directories (say build/ and a developer's second one) never race on one
# node_modules, and the source tree needs no ignore rules. It reruns only when the lock
# file changes or node_modules is missing.

get_filename_component(_pic_root "${CMAKE_CURRENT_LIST_DIR}" DIRECTORY)
set(PIC_GENERATED_DIR "${CMAKE_BINARY_DIR}/generated")
set(PIC_VIEWER_BUNDLE_CPP "${PIC_GENERATED_DIR}/viewer_bundle.cpp")
file(MAKE_DIRECTORY "${PIC_GENERATED_DIR}")

find_program(PIC_NODE node)
find_program(PIC_NPM npm)

function(pic_npm_ci target src_dir work_dir)
  file(MAKE_DIRECTORY "${work_dir}")
  set(stamp "${work_dir}/node_modules/.pic-npm-ci.stamp")
  add_custom_command(OUTPUT "${stamp}"
    COMMAND "${CMAKE_COMMAND}" -E copy_if_different "${src_dir}/package.json"
            "${src_dir}/package-lock.json" "${work_dir}"
    COMMAND "${PIC_NPM}" ci --no-audit --no-fund --loglevel=error
    COMMAND "${CMAKE_COMMAND}" -E touch "${stamp}"
    WORKING_DIRECTORY "${work_dir}"
    DEPENDS "${src_dir}/package.json" "${src_dir}/package-lock.json"
    COMMENT "Installing npm packages of ${src_dir} (npm ci)"
    VERBATIM)
  add_custom_target(${target} DEPENDS "${stamp}")
  set(${target}_STAMP "${stamp}" PARENT_SCOPE)
endfunction()

set(_pic_bundle_js "${PIC_GENERATED_DIR}/viewer.js")
if(PIC_NODE AND PIC_NPM)
  set(_pic_npm_dir "${CMAKE_BINARY_DIR}/npm/viewer")
  pic_npm_ci(pic_viewer_npm "${_pic_root}/viewer" "${_pic_npm_dir}")
  # esbuild resolves 'three' from the entry's directory, so the entry is copied beside the
  # installed node_modules.
  add_custom_command(OUTPUT "${_pic_bundle_js}"
    COMMAND "${CMAKE_COMMAND}" -E copy_if_different "${_pic_root}/viewer/main.js" "${_pic_npm_dir}/main.js"
    COMMAND "${_pic_npm_dir}/node_modules/.bin/esbuild" main.js
            --bundle --format=iife --minify --target=es2020 --charset=ascii
            --legal-comments=eof --log-level=warning "--outfile=${_pic_bundle_js}"
    WORKING_DIRECTORY "${_pic_npm_dir}"
    DEPENDS "${_pic_root}/viewer/main.js" "${pic_viewer_npm_STAMP}"
    COMMENT "Bundling the HTML viewer (esbuild)"
    VERBATIM)
else()
  # Without node the library still builds; `pic view` pages then say what is missing.
  message(WARNING "node/npm not found: the HTML viewer is built without three.js "
                  "(install nodejs and npm for a working viewer)")
  file(WRITE "${_pic_bundle_js}"
       "document.body.textContent='This pic was built without the viewer bundle (node/npm were not found).';\n")
endif()

add_custom_command(OUTPUT "${PIC_VIEWER_BUNDLE_CPP}"
  COMMAND "${CMAKE_COMMAND}" "-DINPUT=${_pic_bundle_js}" "-DOUTPUT=${PIC_VIEWER_BUNDLE_CPP}"
          -DSYMBOL=kViewerBundle -P "${_pic_root}/cmake/embed_text.cmake"
  DEPENDS "${_pic_bundle_js}" "${_pic_root}/cmake/embed_text.cmake"
  COMMENT "Embedding the HTML viewer bundle"
  VERBATIM)
