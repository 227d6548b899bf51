# The browser page (DESIGN §3 web/): `npm ci` when package-lock.json changes, `npm run build` when
# a web source changes, into ${PROJECT_BINARY_DIR}/web, which `edmhmi serve` serves by default.
# Node and npm are needed only here (./edm installs them); nothing is downloaded but npm packages.
find_program(EDM_NPM npm)
set(EDM_WEB_SRC ${PROJECT_SOURCE_DIR}/web)
set(EDM_WEB_OUT ${PROJECT_BINARY_DIR}/web)
if(NOT EDM_NPM)
  message(WARNING "npm not found: the browser page (web/) is not built; `edmhmi serve` needs it "
                  "(./edm installs nodejs and npm)")
  return()
endif()
file(GLOB_RECURSE EDM_WEB_SOURCES CONFIGURE_DEPENDS ${EDM_WEB_SRC}/src/*)
set(EDM_WEB_STAMP ${EDM_WEB_SRC}/node_modules/.package-lock.json)
add_custom_command(
  OUTPUT ${EDM_WEB_STAMP}
  COMMAND ${EDM_NPM} ci --no-audit --no-fund --loglevel=error
  DEPENDS ${EDM_WEB_SRC}/package.json ${EDM_WEB_SRC}/package-lock.json
  WORKING_DIRECTORY ${EDM_WEB_SRC}
  COMMENT "npm ci (web/)"
  VERBATIM)
add_custom_command(
  OUTPUT ${EDM_WEB_OUT}/index.html
  COMMAND ${CMAKE_COMMAND} -E env EDM_WEB_OUT=${EDM_WEB_OUT} ${EDM_NPM} run --silent build
  DEPENDS ${EDM_WEB_STAMP} ${EDM_WEB_SOURCES} ${EDM_WEB_SRC}/index.html
          ${EDM_WEB_SRC}/vite.config.js
  WORKING_DIRECTORY ${EDM_WEB_SRC}
  COMMENT "vite build: web/ -> ${EDM_WEB_OUT}"
  VERBATIM)
add_custom_target(edm_web ALL DEPENDS ${EDM_WEB_OUT}/index.html)
