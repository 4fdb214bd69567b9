# a length0 line before any yarn line
node 1 0 0 0
node 2 1 0 0
length0 0.5 0.5
node 3 2 0 0
node 4 1 -1 0
node 5 1 1 0
yarn cotton 2 1 2 3
yarn wool 1 4 2 5
