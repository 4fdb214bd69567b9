# no node 3
node 1 0 0 0
node 2 1 0 0
node 4 1 -1 0
node 5 1 1 0
yarn cotton 1 1 2
yarn wool 1 4 2 5
