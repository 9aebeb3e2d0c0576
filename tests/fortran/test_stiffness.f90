program test_stiffness
use check
call check_done("test_stiffness")
end program
