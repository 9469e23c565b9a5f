#!/usr/bin/env bash
# new-component.sh NAME [--dest DIR]: create the component bundle DIR/NAME (default DIR:
# bundles/) from rt-core/template/component: pom.xml, contract, RT half in C, its unit test
# (CTest rt.NAME.cycle), README.md. Called by `./arflex new component NAME`.
#
# The native superbuild finds bundles/*/native by itself. Maven cannot glob modules, so
# DIR/pom.xml (bundles/pom.xml, the one list of components: docs/DECISIONS.md D34) gets the
# component twice, added here once each (only if that pom exists and does not list it yet):
# <module>NAME</module>, which builds it, and its dependency, through which the runtime
# assembly (cell/) and the integration tests (build order) get every component. Nothing else
# outside DIR/NAME is edited: the runtime pom, conf/cell.gosh and tests/pom.xml name no
# component by themselves.
#
# Out of the tree (DIR not inside this repository and not a bundles/ folder; D84), the component is a project of its own
# that needs no checkout: its pom.xml (rt-core/template/standalone) has the published
# org.arflex:arflex-parent as parent and builds native/ with CMake against an installed SDK
# (mvn verify -Darflex.sdk=PREFIX), native/CMakeLists.txt finds that SDK by itself
# (find_package(arflex)), and DIR/pom.xml, if any, is left alone.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
TEMPLATE="$ROOT/rt-core/template/component"
STANDALONE_POM="$ROOT/rt-core/template/standalone/pom.xml"

usage() {
  echo "usage: ./arflex new component NAME [--dest DIR]   (NAME: [a-z][a-z0-9-]{0,39})" >&2
  exit 2
}

name="" dest="$ROOT/bundles"
while [ $# -gt 0 ]; do
  case "$1" in
    --dest) dest="${2:?--dest needs a directory}"; shift 2 ;;
    -h|--help) usage ;;
    -*) echo "new component: unknown option '$1'" >&2; usage ;;
    *) [ -z "$name" ] || usage; name="$1"; shift ;;
  esac
done
[ -n "$name" ] || usage
# A contract name, an executable, a CMake target and a Maven module at once: lower case,
# digits and dashes, starting with a letter, at most 40 characters (ARFLEX_ID_MAX).
if ! [[ "$name" =~ ^[a-z][a-z0-9-]{0,39}$ ]]; then
  echo "new component: '$name' is not a valid name: a lower-case letter, then up to 39" \
       "lower-case letters, digits or dashes" >&2
  exit 2
fi
[ -d "$dest" ] || { echo "new component: no directory '$dest'" >&2; exit 2; }
dest=$(cd "$dest" && pwd -P)
target="$dest/$name"
# In the tree: DIR inside this repository, or DIR holding a copy of bundles/pom.xml (a tree built
# elsewhere, the ctest tools.new_component).
case "$dest/" in "$(cd "$ROOT" && pwd -P)/"*) in_tree=true ;; *) in_tree=false ;; esac
if [ -f "$dest/pom.xml" ] && grep -q '<artifactId>arflex-bundles</artifactId>' "$dest/pom.xml"; then
  in_tree=true
fi
if [ -e "$target" ]; then
  echo "new component: $target already exists; nothing changed (pick another name, or" \
       "remove that folder first)" >&2
  exit 1
fi
c_name=${name//-/_}
# The CMake targets NAME and test_C_NAME share one namespace with every other target of the
# superbuild: refuse a name that is already taken there (the configure step would fail).
# (Out of the tree the component is a CMake project of its own.)
clash=""
if $in_tree; then
  clash=$(cd "$ROOT" && grep -rlE --include=CMakeLists.txt \
    "add_(executable|library)\((test_)?($name|$c_name)[ )]" rt-core bundles simulator contracts 2>/dev/null || true)
fi
if [ -n "$clash" ]; then
  echo "new component: '$name' clashes with a CMake target defined in:" $clash >&2
  exit 1
fi

tmp=$(mktemp -d "$dest/.new-$name.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
(cd "$TEMPLATE" && find . -type f) | while read -r rel; do
  out=${rel#./}
  case "$out" in
    native/test_NAME.c) out="native/test_$c_name.c" ;;
    native/NAME.c) out="native/$c_name.c" ;;
    *) out=${out//NAME/$name} ;;
  esac
  mkdir -p "$tmp/$(dirname "$out")"
  sed -e "s/@NAME@/$name/g" -e "s/@C_NAME@/$c_name/g" "$TEMPLATE/$rel" >"$tmp/$out"
done
if ! $in_tree; then
  # the version of the ARFLEX artifacts this tree publishes (mvn install): the parent's
  version=$(sed -n '0,/<version>/s:.*<version>\([^<]*\)</version>.*:\1:p' "$ROOT/pom.xml")
  sed -e "s/@NAME@/$name/g" -e "s/@VERSION@/$version/g" "$STANDALONE_POM" >"$tmp/pom.xml"
fi
mv "$tmp" "$target"
trap - EXIT
echo "created $target"

pom="$dest/pom.xml"
artifact="org.arflex.cell.$name" # the template's pom.xml
if $in_tree && [ -f "$pom" ]; then
  if grep -q "<module>$name</module>" "$pom"; then
    echo "$pom already lists <module>$name</module>"
  elif grep -q '</modules>' "$pom"; then
    awk -v m="    <module>$name</module>" '/<\/modules>/ && !done { print m; done = 1 } { print }' \
      "$pom" >"$pom.tmp" && mv "$pom.tmp" "$pom"
    echo "added <module>$name</module> to $pom (Maven cannot find modules by itself)"
  else
    echo "new component: $pom has no <modules>; add <module>$name</module> yourself" >&2
  fi
  if grep -q "<artifactId>$artifact</artifactId>" "$pom"; then
    echo "$pom already depends on $artifact"
  elif grep -q '</dependencies>' "$pom"; then
    awk -v a="$artifact" '/<\/dependencies>/ && !done {
        print "    <dependency><groupId>org.arflex</groupId><artifactId>" a "</artifactId><version>${project.version}</version>"
        print "      <exclusions><exclusion><groupId>*</groupId><artifactId>*</artifactId></exclusion></exclusions></dependency>"
        done = 1 } { print }' "$pom" >"$pom.tmp" && mv "$pom.tmp" "$pom"
    echo "added the dependency on $artifact to $pom (the runtime's cell/ and the tests get it from there)"
  else
    echo "new component: $pom has no <dependencies>; add a dependency on $artifact yourself" >&2
  fi
fi
if ! $in_tree; then
  cat <<MSG
next (out of the tree: a project of its own, built against the installed SDK):
  install the SDK once, from an ARFLEX build:  cmake --install <arflex>/target/native --prefix SDK
  and the ARFLEX artifacts into your Maven repository (mvn install in the ARFLEX tree), then:
    cd $target && mvn verify -Darflex.sdk=SDK
  see $target/README.md
MSG
  exit 0
fi
cat <<MSG
next:
  configure again (the superbuild finds bundles/*/native when CMake runs), build, test:
    cmake -S . -B build && cmake --build build && (cd build && ctest -R 'rt\\.$name\\.')
  see $target/README.md
MSG
