# a yarn through node 8
node 1 0 0 0
node 2 1 0 0
node 3 2 0 0
node 4 1 -1 0
node 5 1 1 0
yarn cotton 1 1 2 8
