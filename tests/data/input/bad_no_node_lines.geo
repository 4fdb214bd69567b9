# a geometry file with no node lines (issue 39, item 8)
yarn cotton 1 1 2
