mod corpus_counts;
