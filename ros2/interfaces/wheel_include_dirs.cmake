# PyPI's ROS 2 wheels were built in a manylinux container: the CMake targets they export name that
# container's Python and NumPy include folders (/opt/python/cp3XX-cp3XX/...), which no other machine
# has, and CMake refuses to generate with them.  Point those targets at this Python's folders.
execute_process(
  COMMAND ${Python3_EXECUTABLE} -c
    "import sysconfig, numpy; print(sysconfig.get_paths()['include'] + ';' + numpy.get_include(), end='')"
  OUTPUT_VARIABLE _exsce_here
  RESULT_VARIABLE _exsce_failed)
if(_exsce_failed)
  message(FATAL_ERROR "${Python3_EXECUTABLE} cannot tell its include folders (is numpy installed?)")
endif()
list(GET _exsce_here 0 _exsce_python_include)
list(GET _exsce_here 1 _exsce_numpy_include)
get_property(_exsce_imported DIRECTORY PROPERTY IMPORTED_TARGETS)
foreach(_exsce_target IN LISTS _exsce_imported)
  get_target_property(_exsce_dirs ${_exsce_target} INTERFACE_INCLUDE_DIRECTORIES)
  if(_exsce_dirs AND "${_exsce_dirs}" MATCHES "/opt/python/")
    list(TRANSFORM _exsce_dirs REPLACE "^/opt/python/[^/]+/include/python[0-9.]+$" "${_exsce_python_include}")
    list(TRANSFORM _exsce_dirs REPLACE "^/opt/python/.*/numpy/_core/include$" "${_exsce_numpy_include}")
    set_target_properties(${_exsce_target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_exsce_dirs}")
  endif()
endforeach()
