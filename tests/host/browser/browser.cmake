# The live view in a real browser (label "browser"; tests/host/browser/browser_test.py): Debian's
# chromium, driven headless by playwright-core (npm, ./scripts/setup) through view_test.mjs, against
# tissue-host run frog_mouse.toml --mouse. The bad-message test runs in every preset (under the
# sanitizers too: it is the network input's memory safety); the mouse-drag cut needs the frog in
# real time, so not under the sanitizers' slowdown.
find_program(TISSUE_NODE node)
find_program(TISSUE_CHROMIUM chromium PATHS /usr/bin)
find_package(Python3 COMPONENTS Interpreter)
set(TISSUE_PLAYWRIGHT ${PROJECT_SOURCE_DIR}/node_modules/playwright-core/package.json)
if(NOT TISSUE_NODE OR NOT TISSUE_CHROMIUM OR NOT Python3_Interpreter_FOUND OR NOT EXISTS ${TISSUE_PLAYWRIGHT})
  message(WARNING "browser tests off: node, /usr/bin/chromium, python3 or node_modules/playwright-core is missing "
                  "(./scripts/setup installs them)")
  return()
endif()
set(browser_test ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/browser_test.py --host $<TARGET_FILE:tissue-host>
    --scenario ${PROJECT_SOURCE_DIR}/host/scenarios/frog_mouse.toml --script ${CMAKE_CURRENT_LIST_DIR}/view_test.mjs)
add_test(NAME Browser.BadMessagesLeaveTheHostRunningAndAreCounted
         COMMAND ${browser_test} --out ${CMAKE_BINARY_DIR}/browser/bad --mode bad --seconds 3)
set_tests_properties(Browser.BadMessagesLeaveTheHostRunningAndAreCounted
                     PROPERTIES LABELS "host;browser" TIMEOUT 300 RUN_SERIAL TRUE)
if(NOT CMAKE_CXX_FLAGS MATCHES "sanitize")
  add_test(NAME Browser.AMouseDragInThePageCutsTheFrog
           COMMAND ${browser_test} --out ${CMAKE_BINARY_DIR}/browser/cut --mode cut --seconds 3)
  set_tests_properties(Browser.AMouseDragInThePageCutsTheFrog
                       PROPERTIES LABELS "host;browser" TIMEOUT 300 RUN_SERIAL TRUE)
endif()
