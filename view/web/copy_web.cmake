# Copies the page into OUT: index.html and its modules (main.js, draw.js, series.js, plots.js,
# live.js), and from node_modules/three the module build (three.module.js imports three.core.js)
# and OrbitControls. copy_if_different keeps it cheap.
# Usage: cmake -DWEB=<view/web> -DOUT=<build>/view/web -P copy_web.cmake
file(MAKE_DIRECTORY ${OUT}/three)
foreach(f index.html main.js draw.js series.js plots.js live.js)
  file(COPY_FILE ${WEB}/${f} ${OUT}/${f} ONLY_IF_DIFFERENT)
endforeach()
set(three ${WEB}/node_modules/three)
if(NOT EXISTS ${three}/build/three.module.js)
  message(WARNING "view: ${three} is missing (run `npm ci` in ${WEB}); `graspsim view` will say so")
  return()
endif()
foreach(f build/three.module.js build/three.core.js examples/jsm/controls/OrbitControls.js)
  get_filename_component(name ${f} NAME)
  if(EXISTS ${three}/${f})
    file(COPY_FILE ${three}/${f} ${OUT}/three/${name} ONLY_IF_DIFFERENT)
  endif()
endforeach()
