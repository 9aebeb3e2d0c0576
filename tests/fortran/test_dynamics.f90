program test_dynamics
use check
call check_done("test_dynamics")
end program
