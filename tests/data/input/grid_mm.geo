# the grid of grid.geo in mm
unit mm
node 1 0 0 0
node 2 1000 0 0
node 3 2000 0 0
node 4 1000 -1000 0
node 5 1000 1000 0
yarn cotton 4 1 2 3
yarn wool 1 4 2 5
