program test_mesh
use check
call check_done("test_mesh")
end program
