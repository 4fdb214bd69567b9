# The nodes and yarns of valid_scene.nml as a geometry file.
node 2 1.0 0.0 0.0
node 1 0 0 0          # node lines in any order
node 3 2 0 0
NODE 4 1 -1 0
node 5 1 1 0

yarn cotton 4 1 2 3
yarn wool 1 4 &
    2 5
