# Included after project() by the tests' package builds (tests/helpers/ros_packages.py, CMAKE_PROJECT_INCLUDE):
# the tests use generated interface packages from Python only, so the C++ generators and type supports are left
# out (about 40 % of a package's build). rosidl_generate_interfaces() gives no option for it: every generator
# registered on rosidl_generate_idl_interfaces runs, and each C++ one is found by other packages as REQUIRED, so
# CMAKE_DISABLE_FIND_PACKAGE_<pkg> cannot be used. Instead the list of registered generators loses its C++ entries
# whenever it is read, i.e. just before ament_execute_extensions() runs them. The users' builds (sam-codegen
# ros-install, colcon) are untouched.
macro(_sam_tests_python_only var access)
  if(NOT _sam_tests_python_only_busy)  # the filter's own read and write must not run it again
    set(_sam_tests_python_only_busy TRUE)
    list(FILTER AMENT_EXTENSIONS_rosidl_generate_idl_interfaces EXCLUDE REGEX
      "^rosidl_(generator|typesupport|typesupport_fastrtps|typesupport_introspection)_cpp:")
    set(_sam_tests_python_only_busy FALSE)
  endif()
endmacro()
variable_watch(AMENT_EXTENSIONS_rosidl_generate_idl_interfaces _sam_tests_python_only)
