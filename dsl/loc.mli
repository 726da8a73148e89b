(** Source locations: {!Lancer_diag.Loc}, by the name the language's modules use. *)

include module type of struct
  include Lancer_diag.Loc
end
