# SPDX-License-Identifier: GPL-3.0-or-later
# cpack -G DEB: the amfi .deb (scripts/package.sh builds it from a tree
# configured with -DCMAKE_INSTALL_PREFIX=/usr, so that the compiled-in paths,
# the unit and the package's files agree). Runtime dependencies come from
# dpkg-shlibdeps on the installed programs (runtime library packages, never
# -dev); lcm-spy's Java side is a recommendation.
set(CPACK_PACKAGE_NAME amfi)
set(CPACK_PACKAGE_VENDOR "amfi developers")
set(CPACK_PACKAGE_CONTACT "amfi developers <amfi@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
  "bridge weigh-in-motion and damage detection from the bridge's vibration")
set(CPACK_PACKAGE_DESCRIPTION
"amfi weighs every vehicle that crosses a bridge from one or a few
accelerometers (acceleration-based moving force identification) and watches
the inferred weights for a loss of the bridge's stiffness. The package holds
the monitoring daemon amfid with its systemd unit, the offline solver
amfi-solve, the store report amfi-report, the bus monitor amfi-spy and the
vehicle-bridge simulator sim_publisher.")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "systemd")
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "liblcm-bin, sqlite3")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "default-jre, liblcm-java, libjchart2d-java, gnuplot-nox")
set(CPACK_DEBIAN_PACKAGE_HOMEPAGE "file:///usr/share/doc/amfi/README.md")
# The site configuration is a conffile: an upgrade keeps the operator's edits.
configure_file(${PROJECT_SOURCE_DIR}/packaging/debian/conffiles.in
  ${CMAKE_BINARY_DIR}/packaging/conffiles @ONLY)
# The maintainer scripts' lists of units (systemd/CMakeLists.txt's
# AMFI_OPTIONAL_UNITS, installed disabled, and amfid.service):
# AMFI_DEB_UNITS all of them (unmask, try-restart, mask, purge),
# AMFI_DEB_OPTIONAL_UNITS those never enabled (update-state only),
# AMFI_DEB_STOP_UNITS the order prerm stops them in (amfid last: it stores
# every pending passage on SIGTERM, after the instruments' feed stopped).
if(NOT AMFI_OPTIONAL_UNITS)
  message(FATAL_ERROR "AMFI_OPTIONAL_UNITS empty: systemd/ must come before the package")
endif()
list(JOIN AMFI_OPTIONAL_UNITS " " AMFI_DEB_OPTIONAL_UNITS)
set(AMFI_DEB_UNITS "amfid.service ${AMFI_DEB_OPTIONAL_UNITS}")
set(AMFI_DEB_STOP_UNITS "${AMFI_DEB_OPTIONAL_UNITS} amfid.service")
configure_file(${PROJECT_SOURCE_DIR}/packaging/debian/postinst.in
  ${CMAKE_BINARY_DIR}/packaging/postinst @ONLY FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)
configure_file(${PROJECT_SOURCE_DIR}/packaging/debian/prerm.in
  ${CMAKE_BINARY_DIR}/packaging/prerm @ONLY FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)
configure_file(${PROJECT_SOURCE_DIR}/packaging/debian/postrm.in
  ${CMAKE_BINARY_DIR}/packaging/postrm @ONLY FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
  ${CMAKE_BINARY_DIR}/packaging/conffiles
  ${CMAKE_BINARY_DIR}/packaging/postinst
  ${CMAKE_BINARY_DIR}/packaging/prerm
  ${CMAKE_BINARY_DIR}/packaging/postrm)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
set(CPACK_GENERATOR DEB)
include(CPack)
