# The Python module `rtcost` (python/): built when pybind11 and Debian's /usr/bin/python3 (with
# its development files) are found, unless RTCOST_BUILD_PYTHON is set OFF. The module targets
# Debian's interpreter, whose packages (numpy, pandas, dask) rtcost installs; another python3
# first on PATH (pyenv, a venv) is not used unless Python3_EXECUTABLE names it.
if(NOT DEFINED Python3_EXECUTABLE AND EXISTS /usr/bin/python3)
  set(Python3_EXECUTABLE /usr/bin/python3 CACHE FILEPATH "the interpreter the Python module targets")
endif()
find_package(Python3 COMPONENTS Interpreter Development.Module QUIET)
set(PYBIND11_FINDPYTHON ON)
find_package(pybind11 CONFIG QUIET)
set(_rtcost_python_default OFF)
if(Python3_FOUND AND pybind11_FOUND)
  set(_rtcost_python_default ON)
endif()
option(RTCOST_BUILD_PYTHON "Build the Python module (pybind11, Debian's /usr/bin/python3)" ${_rtcost_python_default})
if(RTCOST_BUILD_PYTHON)
  if(NOT Python3_FOUND OR NOT pybind11_FOUND)
    message(FATAL_ERROR "RTCOST_BUILD_PYTHON needs pybind11-dev and python3-dev (scripts/install-deps.sh)")
  endif()
  add_subdirectory(python)
else()
  message(STATUS "rtcost: the Python module is not built (pybind11 or /usr/bin/python3 not found)")
endif()
