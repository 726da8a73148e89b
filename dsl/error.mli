(** The language's errors are the project's diagnostics: {!Lancer_diag.Diagnostic}, by the
    name the language's modules have always used. *)

include module type of struct
  include Lancer_diag.Diagnostic
end
