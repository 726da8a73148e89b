let () = Lancer_cli.Commands.main ()
