# a length0 line whose last value over-stretches its element (issue 39, item 4)
node 1 0 0 0
node 2 1 0 0
node 3 2 0 0
node 4 1 -1 0
node 5 1 1 0
yarn cotton 2 1 2 3
length0 0.5 0.5 0.5 1e-300
yarn wool 1 4 2 5
