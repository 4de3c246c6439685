# at 78bbba4; shared 2-core machine
python scripts/cloud_tree_order.py --sizes 10000 100000 1000000 --repeats 5 --per-class 2 --classes table_pick,box,bookshelf_thin,cage --seeds 3
