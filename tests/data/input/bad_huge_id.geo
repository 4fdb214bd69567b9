# node 5 numbered 2000000000 (the reader used to allocate that many nodes)
node 2 1.0 0.0 0.0
node 1 0 0 0          # node lines in any order
node 3 2 0 0
NODE 4 1 -1 0
node 2000000000 1 1 0

yarn cotton 4 1 2 3
yarn wool 1 4 &
    2 5
