(** Rewrites the generated sections of the language reference: [fields_doc language.md]
    prints the file with each section between [<!-- fields: ID -->] and [<!-- end -->]
    replaced by the table of block [ID] of {!Lancer_dsl.Schema} ([objects]: every shape;
    [common]: the fields every object takes), and the one between [<!-- builtins -->] and
    [<!-- end -->] by the list of built-ins of {!Lancer_dsl.Builtins}. *)
